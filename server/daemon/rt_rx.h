/*
 * What a plant receives on udpm://, read by the loop itself from a UDP socket of its own
 * (rt_rx.c), not through LCM's receive path.
 *
 * Why: LCM 1.3.1 gives every lcm_t that subscribes a thread, two pipes and a receive
 * socket, and waits on them with select(2), which cannot take a descriptor of 1024 or
 * more (glibc aborts the process: "bit out of range 0 - FD_SETSIZE on fd_set"). A plant
 * had two such lcm_t, 12 descriptors: a host of 85 plants crossed 1024 and was killed.
 * Read here, a plant's input costs one socket per port and no thread; the loop reads a
 * batch of datagrams per system call (recvmmsg) when epoll says so.
 *
 * The socket is made as LCM's udpm provider makes its receive socket (the wire stays
 * LCM's: any LCM sender reaches it): bound to INADDR_ANY:PORT with SO_REUSEADDR and
 * SO_REUSEPORT, the group joined on the interface the routing table gives, the URL's
 * recv_buf_size as SO_RCVBUF. Only LCM short messages ("LC02", a sequence number, the
 * channel and its NUL, the payload: every message a controller sends a plant fits one
 * datagram) on the socket's channels are handed on; anything else (another channel, a
 * fragment of a long message "LC03", a datagram cut short) is counted and dropped; `other`,
 * when set, sees every short message. The socket filter (lagsim_net.h) drops most of the
 * rest in the kernel before.
 */
#ifndef LAGSIMD_RT_RX_H
#define LAGSIMD_RT_RX_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define RT_RX_CHANNELS 2
#define RT_RX_DATAGRAM 65536 /* bytes: the largest UDP payload */

/* What the socket hands on: channel k's payloads to on[k](ctx, ...). */
typedef struct rt_rx {
    int fd;                     /* -1: none */
    int nch;
    char ch[RT_RX_CHANNELS][80];
    void (*on[RT_RX_CHANNELS])(void *ctx, const uint8_t *data, size_t len);
    /* every short message, its channel's handler or not (NULL: none): what a
     * subscription to a pattern would hear */
    void (*other)(void *ctx, const char *channel, const uint8_t *data, size_t len);
    void *ctx;
    int64_t dropped;            /* datagrams not handed on (not LC02, another channel) */
    int64_t lost;               /* datagrams the kernel dropped, its buffer full (as of the
                                 * last datagram read: SO_RXQ_OVFL) */
} rt_rx;

/* Takes an LCM short message apart: its channel and payload (pointers into d). Returns
 * true when d is one ("LC02", a NUL-terminated channel within it). Pure. OUT: channel,
 * payload, len */
bool rt_rx_parse(const uint8_t *d, size_t n, const char **channel, const uint8_t **payload,
                 size_t *len);
/* A socket on group:port as LCM's (recv_buf: SO_RCVBUF, 0: the system's). Returns 0, or -1
 * with why in err (r->fd -1). The channels and handlers are the caller's to set. */
int rt_rx_open(rt_rx *r, const char *group, int port, long recv_buf, char *err, size_t errlen);
/* Reads at most max datagrams (fewer when the socket has fewer) and hands each on.
 * Returns the number read (0: nothing waiting). */
int rt_rx_read(rt_rx *r, int max);
/* Reads until a datagram on `marker` with exactly `text` comes, dropping everything read
 * before it, at most timeout_ms; send(ctx) is called at the start and every 100 ms (a
 * marker lost on the way is sent again). Returns 0, or -1 if it did not come. */
int rt_rx_sync(rt_rx *r, const char *marker, const char *text, void (*send)(void *ctx),
               void *ctx, int timeout_ms);
void rt_rx_close(rt_rx *r);

#endif
