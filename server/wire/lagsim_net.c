/*
 * LCM's receive sockets: a filter for where datagrams come from and which channels they
 * carry, and the interface a group is joined on. See lagsim_net.h.
 */
#include "lagsim_net.h"
#include "lagsim_clock.h"

#include <arpa/inet.h>
#include <dirent.h>
#include <linux/filter.h>
#include <linux/if_packet.h>
#include <net/if.h>
#include <netinet/in.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

/* Where an LCM datagram's fields are for a UDP socket filter: offset 0 is the UDP
 * header, its payload starts at 8; an LCM short message is magic (4 bytes), sequence
 * number (4), the channel name and its NUL, the payload. */
#define OFF_MAGIC 8
#define OFF_CHANNEL 16
#define LCM_MAGIC_SHORT 0x4c433032u /* "LC02" */
#define MAX_INSNS 1024 /* the kernel takes up to BPF_MAXINSNS, 4096 */
#define MAX_CHANNEL 63 /* LCM's longest channel name (without its NUL) */

typedef struct prog {
    struct sock_filter in[MAX_INSNS];
    int n;
} prog;

static void emit(prog *p, uint16_t code, uint8_t jt, uint8_t jf, uint32_t k)
{
    if (p->n < MAX_INSNS) p->in[p->n++] = (struct sock_filter){code, jt, jf, k};
}

/* The compares of a name of len bytes: words, then a half word, then a byte. */
static int name_compares(size_t len)
{
    return (int)(len / 4) + (len % 4 >= 2) + (int)(len % 2);
}

/* Emits the compares of the len bytes of `name` against the datagram at `at` (absolute,
 * or after X with ind), each jumping `miss` instructions past the last compare when it
 * differs; falls through when all are equal. */
static void emit_compares(prog *p, const uint8_t *name, size_t len, uint32_t at, bool ind,
                          int miss)
{
    int block = 2 * name_compares(len), done = 0;
    uint16_t mode = ind ? BPF_IND : BPF_ABS;
    for (size_t off = 0; off < len; done += 2) {
        size_t w = len - off >= 4 ? 4 : len - off >= 2 ? 2 : 1;
        uint32_t v = 0;
        for (size_t i = 0; i < w; i++) v = v << 8 | name[off + i];
        uint16_t size = w == 4 ? BPF_W : w == 2 ? BPF_H : BPF_B;
        emit(p, BPF_LD | size | mode, 0, 0, at + (uint32_t)off);
        emit(p, BPF_JMP | BPF_JEQ | BPF_K, 0, (uint8_t)(block - done - 2 + miss), v);
        off += w;
    }
}

/* Emits: if the channel at OFF_CHANNEL is `name` (with its NUL), accept; else fall
 * through to the next block. */
static void emit_channel(prog *p, const char *name)
{
    emit_compares(p, (const uint8_t *)name, strlen(name) + 1, OFF_CHANNEL, false, 1);
    emit(p, BPF_RET | BPF_K, 0, 0, 0xffffffffu);
}

/* Emits the channels that end in one of the suffixes: the channel's NUL found by a look
 * at each length 1 to MAX_CHANNEL (its length into X), then each suffix compared right
 * before it (with at least one byte of prefix before the suffix); else drop. */
static void emit_suffixes(prog *p, const char *const *suffixes, int ns)
{
    int check = p->n + 4 * MAX_CHANNEL + 1; /* where the suffixes are compared */
    for (int len = 1; len <= MAX_CHANNEL; len++) {
        emit(p, BPF_LD | BPF_B | BPF_ABS, 0, 0, (uint32_t)(OFF_CHANNEL + len));
        emit(p, BPF_JMP | BPF_JEQ | BPF_K, 0, 2, 0);
        emit(p, BPF_LDX | BPF_W | BPF_IMM, 0, 0, (uint32_t)len);
        emit(p, BPF_JMP | BPF_JA, 0, 0, (uint32_t)(check - p->n - 1));
    }
    emit(p, BPF_RET | BPF_K, 0, 0, 0); /* no NUL within LCM's longest name */
    for (int i = 0; i < ns; i++) {
        size_t m = strlen(suffixes[i]);
        int block = 2 * name_compares(m) + 1; /* the compares and the accept */
        emit(p, BPF_MISC | BPF_TXA, 0, 0, 0);
        emit(p, BPF_JMP | BPF_JGE | BPF_K, 0, (uint8_t)block, (uint32_t)(m + 1));
        /* the suffix's first byte at OFF_CHANNEL + X - m */
        emit_compares(p, (const uint8_t *)suffixes[i], m, (uint32_t)(OFF_CHANNEL - (int)m), true,
                      1);
        emit(p, BPF_RET | BPF_K, 0, 0, 0xffffffffu);
    }
    emit(p, BPF_RET | BPF_K, 0, 0, 0);
}

/* Emits: if the channel at OFF_CHANNEL is `name` (with its NUL), drop; else fall through. */
static void emit_drop_channel(prog *p, const char *name)
{
    emit_compares(p, (const uint8_t *)name, strlen(name) + 1, OFF_CHANNEL, false, 1);
    emit(p, BPF_RET | BPF_K, 0, 0, 0);
}

/* The whole program: [from this host] LC02, none of the `except` channels, one of the
 * channels or a channel ending in one of the suffixes; else drop. Every jump is short (a
 * drop next to what fails), but the suffixes' jumps to their compares (BPF_JA takes 32
 * bits). */
static int build(prog *p, bool host_only, const char *const *channels, int n,
                 const char *const *suffixes, int ns, const char *const *except, int ne,
                 char *err, size_t errlen)
{
    p->n = 0;
    for (int i = 0; i < n + ns + ne; i++) { /* a name the compares can hold; a suffix LCM can */
        const char *name = i < n ? channels[i] : i < n + ns ? suffixes[i - n] : except[i - n - ns];
        if (strlen(name) > (i < n || i >= n + ns ? 64 + 8 : MAX_CHANNEL - 1) || !name[0]) {
            snprintf(err, errlen, "channel name '%s' too long for the filter", name);
            return -1;
        }
    }
    if (host_only) {
        unsigned lo = if_nametoindex("lo");
        /* looped back from a local sender, or in on the loopback interface */
        emit(p, BPF_LD | BPF_W | BPF_ABS, 0, 0, (uint32_t)(SKF_AD_OFF + SKF_AD_PKTTYPE));
        emit(p, BPF_JMP | BPF_JEQ | BPF_K, 3, 0, PACKET_LOOPBACK);
        emit(p, BPF_LD | BPF_W | BPF_ABS, 0, 0, (uint32_t)(SKF_AD_OFF + SKF_AD_IFINDEX));
        emit(p, BPF_JMP | BPF_JEQ | BPF_K, 1, 0, lo ? lo : 1);
        emit(p, BPF_RET | BPF_K, 0, 0, 0);
    }
    emit(p, BPF_LD | BPF_W | BPF_ABS, 0, 0, OFF_MAGIC);
    emit(p, BPF_JMP | BPF_JEQ | BPF_K, 1, 0, LCM_MAGIC_SHORT);
    emit(p, BPF_RET | BPF_K, 0, 0, 0);
    for (int i = 0; i < ne; i++) emit_drop_channel(p, except[i]);
    for (int i = 0; i < n; i++) emit_channel(p, channels[i]);
    if (ns > 0) emit_suffixes(p, suffixes, ns);
    else emit(p, BPF_RET | BPF_K, 0, 0, 0);
    if (p->n >= MAX_INSNS) {
        snprintf(err, errlen, "too many channels for the filter");
        return -1;
    }
    return 0;
}

/* The sockets this process had before it made its own (lag_net_note_inherited): a parent
 * that forked the daemon without close-on-exec shares them, and a filter on one would
 * filter the parent's traffic too. */
#define LAG_NET_INHERITED_MAX 64
static int inherited[LAG_NET_INHERITED_MAX];
static int n_inherited;

/* Calls fn(fd, user) for every AF_INET datagram socket of this process bound to `port`
 * (any port when port < 0) until fn returns non-zero; returns what fn returned (0: all
 * visited), or -1 if /proc/self/fd cannot be read. */
static int each_udp_socket(int port, int (*fn)(int fd, void *user), void *user)
{
    DIR *d = opendir("/proc/self/fd");
    if (!d) return -1;
    int rc = 0;
    struct dirent *e;
    while (rc == 0 && (e = readdir(d)) != NULL) {
        char *end;
        long fd = strtol(e->d_name, &end, 10);
        if (*end != '\0' || fd < 0 || fd == dirfd(d)) continue;
        struct stat st;
        if (fstat((int)fd, &st) != 0 || !S_ISSOCK(st.st_mode)) continue;
        int type = 0, domain = 0;
        socklen_t sl = sizeof type;
        if (getsockopt((int)fd, SOL_SOCKET, SO_TYPE, &type, &sl) != 0 || type != SOCK_DGRAM)
            continue;
        sl = sizeof domain;
        if (getsockopt((int)fd, SOL_SOCKET, SO_DOMAIN, &domain, &sl) != 0 || domain != AF_INET)
            continue;
        struct sockaddr_in a;
        sl = sizeof a;
        if (getsockname((int)fd, (struct sockaddr *)&a, &sl) != 0) continue;
        if (port >= 0 && ntohs(a.sin_port) != port) continue;
        rc = fn((int)fd, user);
    }
    closedir(d);
    return rc;
}

static int note_one(int fd, void *user)
{
    (void)user;
    if (n_inherited < LAG_NET_INHERITED_MAX) inherited[n_inherited++] = fd;
    return 0;
}

void lag_net_note_inherited(void)
{
    static bool noted; /* the first call only: later, the process's own sockets exist (a
                        * host's other plants), and they are not a parent's */
    if (noted) return;
    noted = true;
    n_inherited = 0;
    each_udp_socket(-1, note_one, NULL);
}

typedef struct attach {
    struct sock_fprog fp;
    int found;
} attach;

static int attach_one(int fd, void *user)
{
    attach *a = user;
    for (int k = 0; k < n_inherited; k++)
        if (inherited[k] == fd) return 0; /* not ours */
    if (setsockopt(fd, SOL_SOCKET, SO_ATTACH_FILTER, &a->fp, sizeof a->fp) != 0) return 1;
    a->found++;
    return 0;
}

int lag_net_filter(int port, bool host_only, const char *const *channels, int n, char *err,
                  size_t errlen)
{
    return lag_net_filter_suffixes(port, host_only, channels, n, NULL, 0, err, errlen);
}

int lag_net_filter_suffixes(int port, bool host_only, const char *const *channels, int n,
                            const char *const *suffixes, int ns, char *err, size_t errlen)
{
    if (n < 1 || n > LAG_NET_MAX_FILTER_CHANNELS || ns < 0 || ns > LAG_NET_MAX_FILTER_CHANNELS) {
        snprintf(err, errlen, "filter: 1 to %d channels, 0 to %d suffixes",
                 LAG_NET_MAX_FILTER_CHANNELS, LAG_NET_MAX_FILTER_CHANNELS);
        return -1;
    }
    static prog p; /* one thread sets filters, at start */
    if (build(&p, host_only, channels, n, suffixes, ns, NULL, 0, err, errlen) < 0) return -1;
    attach a = {{(unsigned short)p.n, p.in}, 0};
    int rc = each_udp_socket(port, attach_one, &a);
    if (rc < 0) {
        snprintf(err, errlen, "cannot list /proc/self/fd to find LCM's receive socket");
        return -1;
    }
    if (rc > 0) {
        snprintf(err, errlen, "cannot attach a socket filter to LCM's receive socket "
                 "(port %d)", port);
        return -1;
    }
    return a.found;
}

int lag_net_filter_fd(int fd, bool host_only, const char *const *channels, int n,
                      const char *const *suffixes, int ns, const char *const *except, int ne,
                      char *err, size_t errlen)
{
    if (n < 0 || n > LAG_NET_MAX_FILTER_CHANNELS || ns < 0 || ns > LAG_NET_MAX_FILTER_CHANNELS ||
        ne < 0 || ne > LAG_NET_MAX_FILTER_CHANNELS || n + ns < 1) {
        snprintf(err, errlen, "filter: 0 to %d channels, suffixes and exceptions each, a "
                 "channel or a suffix at least", LAG_NET_MAX_FILTER_CHANNELS);
        return -1;
    }
    static prog p; /* one thread sets filters */
    if (build(&p, host_only, channels, n, suffixes, ns, except, ne, err, errlen) < 0) return -1;
    struct sock_fprog fp = {(unsigned short)p.n, p.in};
    if (setsockopt(fd, SOL_SOCKET, SO_ATTACH_FILTER, &fp, sizeof fp) != 0) {
        snprintf(err, errlen, "cannot attach a socket filter (descriptor %d)", fd);
        return -1;
    }
    return 0;
}

/* ---------------------------------------------------------------- sync */
typedef struct marker {
    char text[96];
    bool seen;
} marker;

static void on_marker(const lcm_recv_buf_t *rb, const char *ch, void *user)
{
    (void)ch;
    marker *m = user;
    size_t n = strlen(m->text);
    if (rb->data_size == n && memcmp(rb->data, m->text, n) == 0) m->seen = true;
}

static int64_t mono_ms(void) { return lag_clock_mono_ns() / 1000000; }

int lag_net_sync(lcm_t *lcm, int timeout_ms)
{
    static unsigned counter;
    marker m = {.seen = false};
    int64_t t = lag_clock_mono_ns();
    snprintf(m.text, sizeof m.text, "lagsim %ld sync %u %lld.%09lld", (long)getpid(), ++counter,
             (long long)(t / 1000000000), (long long)(t % 1000000000));
    lcm_subscription_t *sub = lcm_subscribe(lcm, LAG_NET_MARKER_CHANNEL, on_marker, &m);
    if (!sub) return -1;
    lcm_subscription_set_queue_capacity(sub, 1000);
    int64_t end = mono_ms() + timeout_ms, next_send = 0;
    while (!m.seen) {
        int64_t now = mono_ms();
        if (now >= end) break;
        if (now >= next_send) { /* a marker lost on the way is sent again */
            lcm_publish(lcm, LAG_NET_MARKER_CHANNEL, m.text, (unsigned)strlen(m.text));
            next_send = now + 100;
        }
        int64_t wait = next_send < end ? next_send - now : end - now;
        lcm_handle_timeout(lcm, (int)(wait > 0 ? wait : 1));
    }
    lcm_unsubscribe(lcm, sub);
    return m.seen ? 0 : -1;
}

/* ---------------------------------------------------------------- route */
int lag_net_group_iface(const char *group, char *ifname, size_t len)
{
    snprintf(ifname, len, "?");
    struct in_addr g;
    if (inet_pton(AF_INET, group, &g) != 1) return -1;
    FILE *f = fopen("/proc/net/route", "r");
    if (!f) return 0; /* unknown, not absent */
    char line[256], best[IF_NAMESIZE + 1] = "";
    int best_bits = -1;
    unsigned long best_metric = 0;
    if (!fgets(line, sizeof line, f)) line[0] = '\0'; /* the header */
    while (fgets(line, sizeof line, f)) {
        char iface[IF_NAMESIZE + 1];
        unsigned long dest, gw, flags, refcnt, use, metric, mask;
        if (sscanf(line, "%16s %lx %lx %lx %lu %lu %lu %lx", iface, &dest, &gw, &flags, &refcnt,
                   &use, &metric, &mask) != 8)
            continue;
        if (!(flags & 1UL)) continue; /* RTF_UP */
        if ((g.s_addr & (uint32_t)mask) != (uint32_t)dest) continue;
        int bits = __builtin_popcount((unsigned)mask);
        if (bits > best_bits || (bits == best_bits && metric < best_metric)) {
            best_bits = bits;
            best_metric = metric;
            snprintf(best, sizeof best, "%s", iface);
        }
    }
    fclose(f);
    if (best_bits < 0) return -1;
    snprintf(ifname, len, "%s", best);
    return 0;
}
