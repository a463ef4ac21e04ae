/*
 * A plant's input read by the loop (rt_rx.h).
 */
#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdio.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "lagsim_clock.h"
#include "rt_rx.h"

#define RT_RX_BATCH 16 /* datagrams per recvmmsg */

bool rt_rx_parse(const uint8_t *d, size_t n, const char **channel, const uint8_t **payload,
                 size_t *len)
{
    if (n < 9 || memcmp(d, "LC02", 4) != 0) return false;
    const uint8_t *nul = memchr(d + 8, '\0', n - 8);
    if (!nul) return false;
    *channel = (const char *)d + 8;
    *payload = nul + 1;
    *len = n - (size_t)(nul + 1 - d);
    return true;
}

int rt_rx_open(rt_rx *r, const char *group, int port, long recv_buf, char *err, size_t errlen)
{
    r->fd = socket(AF_INET, SOCK_DGRAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    int one = 1;
    struct sockaddr_in a = {.sin_family = AF_INET, .sin_port = htons((uint16_t)port),
                            .sin_addr.s_addr = htonl(INADDR_ANY)};
    struct ip_mreq mr = {.imr_interface.s_addr = htonl(INADDR_ANY)};
    const char *what = "socket";
    if (r->fd >= 0 && (what = "SO_REUSEADDR",
                       setsockopt(r->fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one) == 0) &&
        (what = "SO_REUSEPORT",
         setsockopt(r->fd, SOL_SOCKET, SO_REUSEPORT, &one, sizeof one) == 0) &&
        (what = "SO_RXQ_OVFL", /* the kernel's drops, with each datagram (r->lost) */
         setsockopt(r->fd, SOL_SOCKET, SO_RXQ_OVFL, &one, sizeof one) == 0) &&
        (what = "SO_RCVBUF", recv_buf <= 0 || setsockopt(r->fd, SOL_SOCKET, SO_RCVBUF,
                                                         &(int){(int)recv_buf}, sizeof(int)) == 0) &&
        (what = "bind", bind(r->fd, (struct sockaddr *)&a, sizeof a) == 0) &&
        (what = "the group", inet_pton(AF_INET, group, &mr.imr_multiaddr) == 1) &&
        (what = "IP_ADD_MEMBERSHIP",
         setsockopt(r->fd, IPPROTO_IP, IP_ADD_MEMBERSHIP, &mr, sizeof mr) == 0))
        return 0;
    snprintf(err, errlen, "cannot receive on %s:%d (%s: %s)", group, port, what, strerror(errno));
    rt_rx_close(r);
    return -1;
}

/* One datagram: handed on to its channel's handler, or counted. */
static void hand_on(rt_rx *r, const uint8_t *d, size_t n)
{
    const char *ch;
    const uint8_t *payload;
    size_t len;
    if (!rt_rx_parse(d, n, &ch, &payload, &len)) {
        r->dropped++;
        return;
    }
    int k = 0;
    while (k < r->nch && strcmp(ch, r->ch[k]) != 0) k++;
    if (k < r->nch) r->on[k](r->ctx, payload, len);
    else if (!r->other) r->dropped++;
    if (r->other) r->other(r->ctx, ch, payload, len);
}

/* The socket's drop count (SO_RXQ_OVFL) a datagram came with, into r->lost. */
static void note_lost(rt_rx *r, struct msghdr *h)
{
    for (struct cmsghdr *c = CMSG_FIRSTHDR(h); c; c = CMSG_NXTHDR(h, c))
        if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_RXQ_OVFL) {
            uint32_t n;
            memcpy(&n, CMSG_DATA(c), sizeof n);
            r->lost = n;
        }
}

int rt_rx_read(rt_rx *r, int max)
{
    static uint8_t buf[RT_RX_BATCH][RT_RX_DATAGRAM]; /* the loop's one thread reads */
    static uint8_t ctl[RT_RX_BATCH][CMSG_SPACE(sizeof(uint32_t))];
    struct mmsghdr mm[RT_RX_BATCH];
    struct iovec iov[RT_RX_BATCH];
    int done = 0;
    while (r->fd >= 0 && done < max) {
        int want = max - done < RT_RX_BATCH ? max - done : RT_RX_BATCH;
        for (int k = 0; k < want; k++) {
            iov[k] = (struct iovec){buf[k], sizeof buf[k]};
            mm[k] = (struct mmsghdr){.msg_hdr = {.msg_iov = &iov[k], .msg_iovlen = 1,
                                                 .msg_control = ctl[k],
                                                 .msg_controllen = sizeof ctl[k]}};
        }
        int got = recvmmsg(r->fd, mm, (unsigned)want, MSG_DONTWAIT, NULL);
        if (got <= 0) break;
        for (int k = 0; k < got; k++) {
            note_lost(r, &mm[k].msg_hdr);
            hand_on(r, buf[k], mm[k].msg_len);
        }
        done += got;
        if (got < want) break;
    }
    return done;
}

/* The marker's datagram, if d is it. */
static bool is_marker(const uint8_t *d, size_t n, const char *marker, const char *text)
{
    const char *ch;
    const uint8_t *payload;
    size_t len;
    return rt_rx_parse(d, n, &ch, &payload, &len) && !strcmp(ch, marker) &&
           len == strlen(text) && !memcmp(payload, text, len);
}

int rt_rx_sync(rt_rx *r, const char *marker, const char *text, void (*send)(void *ctx),
               void *ctx, int timeout_ms)
{
    static uint8_t buf[RT_RX_DATAGRAM];
    int64_t end = lag_clock_mono_ns() + (int64_t)timeout_ms * 1000000, next = 0;
    for (int64_t now; r->fd >= 0 && (now = lag_clock_mono_ns()) < end;) {
        if (now >= next) {
            send(ctx);
            next = now + 100000000;
        }
        ssize_t n;
        while ((n = recv(r->fd, buf, sizeof buf, MSG_DONTWAIT)) >= 0)
            if (is_marker(buf, (size_t)n, marker, text)) return 0;
        struct pollfd pf = {r->fd, POLLIN, 0};
        int64_t wait = (next < end ? next : end) - lag_clock_mono_ns();
        poll(&pf, 1, wait > 0 ? (int)(wait / 1000000) + 1 : 0);
    }
    return -1;
}

void rt_rx_close(rt_rx *r)
{
    if (r->fd >= 0) close(r->fd);
    r->fd = -1;
}
