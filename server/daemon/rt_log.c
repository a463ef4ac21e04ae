/*
 * lagsimd --log: the ring and its writer thread (see rt_log.h).
 *
 * Positions are byte counters that only grow (head: put by the loop; tail: written by the
 * writer); the ring index is the counter modulo the ring's size, so a record may wrap
 * around the end (it is copied in two parts, and written with two iovecs).
 *
 * The writer writes in batches: after writing what the ring held it sleeps up to
 * RT_LOG_BATCH_MS (so a record reaches the file within that, as lcm-logger flushes every
 * 100 ms), and the loop wakes it early only when the ring is 1/8 full: a few system calls
 * a second instead of one or two per record. Waking it without a lock: the writer sets
 * `sleeping`, then looks at head once more before it waits on the semaphore; the loop
 * publishes head, then looks at `sleeping` and posts when it is set. Both accesses are
 * sequentially consistent, so at least one side sees the other's store. sem_post never
 * blocks.
 */
#include "rt_log.h"

#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <semaphore.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <time.h>
#include <unistd.h>

#include "lagsim_clock.h"
#include "lagsim_log.h"
#include "lagsim_out.h"

#define RT_LOG_BATCH_MS 100 /* the writer's longest sleep with records waiting */
#define RT_LOG_CUTS 64      /* --split-mb: files the writer may be behind by and still cut each
                             * where it was due (more: a file grows by what it is behind) */

struct rt_log {
    int fd;
    char path[4096];           /* --log FILE */
    uint8_t *ring;
    size_t cap;
    _Atomic uint64_t head;     /* bytes put: written by the loop only */
    _Atomic uint64_t tail;     /* bytes written to the file: by the writer only */
    _Atomic int sleeping;      /* the writer waits on `wake` */
    _Atomic int closing;       /* rt_log_close: write what is left, then end */
    _Atomic int error;         /* errno of the failed write; the writer has ended */
    sem_t wake;
    pthread_t thread;
    bool thread_started;
    /* a series: what the writer does when it goes on in the next file */
    bool series;
    int keep;
    int64_t split;             /* bytes per file, 0: never split */
    uint64_t first;            /* the first file's number */
    _Atomic uint64_t number;   /* the current file's number: written by the writer only */
    /* the loop's marks, in order: the writer goes on in the next file at each position
     * (bytes put); a queue of one producer and one consumer, as the ring */
    _Atomic uint64_t cuts[RT_LOG_CUTS];
    _Atomic uint64_t cuts_put, cuts_taken;
    _Atomic int64_t files, removed, removed_bytes;
    _Atomic int prune_error;
    uint64_t file_start;       /* the loop's: the position its current file began at */
    /* the loop's own counters */
    int64_t records, dropped_full, dropped_in, dropped_failed, too_large;
};

/* ---------------------------------------------------------------- the writer thread */
static void deadline_in(struct timespec *ts, long ms)
{
    lag_clock_wall_timespec(ts); /* sem_timedwait's clock */
    ts->tv_sec += ms / 1000;
    ts->tv_nsec += (ms % 1000) * 1000000L;
    if (ts->tv_nsec >= 1000000000L) {
        ts->tv_sec++;
        ts->tv_nsec -= 1000000000L;
    }
}

/* The writer sleeps until the ring holds a batch (the loop posts), RT_LOG_BATCH_MS pass,
 * or close is asked for. */
static void nap(rt_log *l, uint64_t tail)
{
    atomic_store(&l->sleeping, 1);
    uint64_t head = atomic_load(&l->head);
    if (head - tail < l->cap / 8 && !atomic_load(&l->closing)) {
        struct timespec ts;
        deadline_in(&ts, RT_LOG_BATCH_MS);
        sem_timedwait(&l->wake, &ts); /* a cancellation point */
    }
    atomic_store(&l->sleeping, 0);
}

/* --keep: the series' oldest beyond `keep` removed, counted; a failure is kept (said by
 * the loop) and stops nothing. */
static void prune(rt_log *l, uint64_t current)
{
    if (!l->series || l->keep < 1) return;
    char err[512];
    int64_t freed = 0;
    int n = lag_out_series_prune("--log", l->path, l->keep, current, &freed, err, sizeof err);
    if (n < 0) {
        atomic_store(&l->prune_error, errno ? errno : EIO);
        return;
    }
    atomic_fetch_add(&l->removed, n);
    atomic_fetch_add(&l->removed_bytes, freed);
}

/* The writer goes on in the series' next file (the loop's mark reached). False, with
 * l->error set, when it cannot. */
static bool next_file(rt_log *l)
{
    char name[4096], err[512];
    uint64_t number;
    int fd = lag_out_series_open("--log", l->path, 0, name, sizeof name, &number, err,
                                 sizeof err);
    int e = errno;
    if (fd < 0 || close(l->fd) != 0) {
        if (fd >= 0) {
            e = errno;
            close(fd);
        }
        atomic_store(&l->error, e ? e : EIO);
        return false;
    }
    l->fd = fd;
    atomic_store(&l->number, number);
    atomic_fetch_add(&l->files, 1);
    prune(l, number);
    return true;
}

static void *writer(void *arg)
{
    rt_log *l = arg;
    uint64_t tail = atomic_load(&l->tail);
    bool napped = false; /* a nap since the last write: what is there goes out */
    for (;;) {
        uint64_t head = atomic_load_explicit(&l->head, memory_order_acquire);
        uint64_t taken = atomic_load(&l->cuts_taken);
        uint64_t cut = taken < atomic_load(&l->cuts_put) /* stored after head: cut <= head */
                       ? atomic_load(&l->cuts[taken % RT_LOG_CUTS]) : 0;
        bool closing = atomic_load(&l->closing);
        if (head == tail && closing) break;
        if (cut != 0 && tail == cut) {
            if (!next_file(l)) break;
            atomic_store(&l->cuts_taken, taken + 1);
            continue;
        }
        uint64_t end = cut != 0 && cut < head ? cut : head;
        if (end == tail || (end - tail < l->cap / 8 && !napped && !closing && end == head)) {
            nap(l, tail);
            napped = true;
            continue;
        }
        napped = false;
        size_t n = (size_t)(end - tail), off = (size_t)(tail % l->cap);
        size_t first = n < l->cap - off ? n : l->cap - off;
        struct iovec iov[2] = {{l->ring + off, first}, {l->ring, n - first}};
        ssize_t w = writev(l->fd, iov, n > first ? 2 : 1); /* a cancellation point */
        if (w < 0 && errno == EINTR) continue;
        if (w <= 0) {
            atomic_store(&l->error, w < 0 && errno != 0 ? errno : EIO);
            break;
        }
        tail += (uint64_t)w;
        atomic_store_explicit(&l->tail, tail, memory_order_release);
    }
    return NULL;
}

/* ---------------------------------------------------------------- open / close */
static rt_log *fail_open(rt_log *l, char *err, size_t errlen, const char *fmt, ...)
    __attribute__((format(printf, 4, 5)));
static rt_log *fail_open(rt_log *l, char *err, size_t errlen, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(err, errlen, fmt, ap);
    va_end(ap);
    if (l) {
        if (l->fd >= 0) close(l->fd);
        free(l->ring);
        free(l);
    }
    return NULL;
}

/* The file: FILE by lag_out_open's rules, or the series' next file (then --keep). Returns
 * its descriptor, or -1 with err (and *refused for a refusal by the rules). */
static int open_file(rt_log *l, const rt_log_conf *c, bool *refused, char *err,
                     size_t errlen)
{
    /* O_NONBLOCK: a FIFO without a reader fails at once (ENXIO) instead of blocking the
     * start; it is cleared afterwards, so that only the writer thread ever waits */
    int fd;
    if (c->series) {
        char name[4096];
        uint64_t number;
        fd = lag_out_series_open("--log", c->path, O_NONBLOCK, name, sizeof name, &number,
                                 err, errlen);
        if (fd >= 0) {
            l->first = number;
            atomic_store(&l->number, number);
        }
    } else {
        const char *inputs[1] = {c->input};
        fd = lag_out_open("--log", c->path, c->force, inputs, 1, O_NONBLOCK, err, errlen);
    }
    if (fd == LAG_OUT_REFUSED && refused) *refused = true;
    if (fd < 0) return -1;
    int fl = fcntl(fd, F_GETFL);
    if (fl < 0 || fcntl(fd, F_SETFL, fl & ~O_NONBLOCK) < 0) {
        snprintf(err, errlen, "--log %s: %s", c->path, strerror(errno));
        close(fd);
        return -1;
    }
    return fd;
}

rt_log *rt_log_open(const rt_log_conf *c, bool *refused, char *err, size_t errlen)
{
    size_t ring_bytes = c->ring;
    if (refused) *refused = false;
    if (ring_bytes < RT_LOG_RING_MIN) ring_bytes = RT_LOG_RING_MIN;
    if (ring_bytes > RT_LOG_RING_MAX) ring_bytes = RT_LOG_RING_MAX;
    const char *path = c->path;
    rt_log *l = calloc(1, sizeof *l);
    if (!l) return fail_open(NULL, err, errlen, "--log %s: out of memory", path);
    l->fd = -1;
    if (snprintf(l->path, sizeof l->path, "%s", path) >= (int)sizeof l->path)
        return fail_open(l, err, errlen, "--log: a path longer than %zu bytes",
                         sizeof l->path - 1);
    l->series = c->series;
    l->keep = c->series ? c->keep : 0;
    l->split = c->series ? c->split : 0;
    char oerr[512];
    l->fd = open_file(l, c, refused, oerr, sizeof oerr);
    if (l->fd < 0) return fail_open(l, err, errlen, "%s", oerr);
    atomic_store(&l->files, 1);
    l->ring = malloc(ring_bytes);
    if (!l->ring) return fail_open(l, err, errlen, "--log %s: cannot allocate a ring of %zu bytes",
                                   path, ring_bytes);
    l->cap = ring_bytes;
    prune(l, l->first); /* before the writer starts: nothing else touches the counters */
    if (sem_init(&l->wake, 0, 0) != 0)
        return fail_open(l, err, errlen, "--log %s: %s", path, strerror(errno));
    int rc = pthread_create(&l->thread, NULL, writer, l);
    if (rc != 0) {
        sem_destroy(&l->wake);
        return fail_open(l, err, errlen, "--log %s: cannot start the writer thread: %s", path,
                         strerror(rc));
    }
    l->thread_started = true;
    return l;
}

/* A log whose writer could not be stopped: kept reachable (the thread may still touch
 * it) until the process ends. */
static rt_log *g_abandoned;

int rt_log_close(rt_log *l, int stall_ms, rt_log_stats *final)
{
    if (!l) return 0;
    atomic_store(&l->closing, 1);
    sem_post(&l->wake);
    bool joined = false;
    uint64_t seen = atomic_load(&l->tail);
    int64_t last = lag_clock_mono_ns();
    while (!joined) {
        struct timespec ts;
        deadline_in(&ts, 50);
        if (pthread_timedjoin_np(l->thread, NULL, &ts) == 0) {
            joined = true;
            break;
        }
        int64_t now = lag_clock_mono_ns();
        uint64_t t = atomic_load(&l->tail);
        if (t != seen) { /* progress: the stall clock starts again */
            seen = t;
            last = now;
            continue;
        }
        double idle_ms = (double)(now - last) * 1e-6;
        if (idle_ms < stall_ms) continue;
        /* stalled: cancel it (it waits in writev or sem_timedwait, both cancellation
         * points); what it still held is lost */
        pthread_cancel(l->thread);
        deadline_in(&ts, 1000);
        joined = pthread_timedjoin_np(l->thread, NULL, &ts) == 0;
        if (!joined) {
            if (atomic_load(&l->error) == 0) atomic_store(&l->error, ETIMEDOUT);
            rt_log_get_stats(l, final ? final : &(rt_log_stats){0});
            g_abandoned = l;
            return -1;
        }
        if (atomic_load(&l->error) == 0) atomic_store(&l->error, ETIMEDOUT);
    }
    rt_log_stats st;
    rt_log_get_stats(l, &st);
    if (close(l->fd) != 0 && st.error == 0) {
        st.error = errno;
        atomic_store(&l->error, errno);
    }
    sem_destroy(&l->wake);
    free(l->ring);
    free(l);
    if (final) *final = st;
    bool complete = st.error == 0 && st.written == st.bytes && st.dropped_full == 0 &&
                    st.dropped_in == 0 && st.dropped_failed == 0 && st.too_large == 0;
    return complete ? 0 : -1;
}

/* ---------------------------------------------------------------- the loop's side */
static void ring_copy(rt_log *l, uint64_t pos, const void *src, size_t n)
{
    size_t off = (size_t)(pos % l->cap);
    size_t first = n < l->cap - off ? n : l->cap - off;
    memcpy(l->ring + off, src, first);
    if (n > first) memcpy(l->ring, (const uint8_t *)src + first, n - first);
}

bool rt_log_put(rt_log *l, rt_log_dir dir, int64_t timestamp_us, const char *channel,
                const void *data, size_t len)
{
    if (atomic_load_explicit(&l->error, memory_order_relaxed) != 0) {
        l->dropped_failed++;
        return false;
    }
    size_t chlen = strnlen(channel, LAG_LOG_CHANNEL_MAX + 1);
    size_t need = LAG_LOG_HEADER_SIZE + chlen + len;
    if (chlen < 1 || chlen > LAG_LOG_CHANNEL_MAX || len > l->cap / 4 || need > l->cap / 4) {
        l->too_large++;
        return false;
    }
    uint64_t head = atomic_load_explicit(&l->head, memory_order_relaxed);
    uint64_t tail = atomic_load_explicit(&l->tail, memory_order_acquire);
    size_t used = (size_t)(head - tail);
    size_t limit = dir == RT_LOG_IN ? l->cap / 4 * 3 : l->cap;
    if (used + need > limit) {
        if (dir == RT_LOG_IN) l->dropped_in++;
        else l->dropped_full++;
        return false;
    }
    uint8_t h[LAG_LOG_HEADER_SIZE];
    lag_log_put_header(h, l->records, timestamp_us, (int32_t)chlen, (int32_t)len);
    ring_copy(l, head, h, sizeof h);
    ring_copy(l, head + sizeof h, channel, chlen);
    if (len) ring_copy(l, head + sizeof h + chlen, data, len);
    atomic_store(&l->head, head + need); /* seq_cst: see the comment at the top */
    /* --split-mb: the file holds `split` bytes once this record is written; the writer
     * goes on in the next one after it (a writer more than RT_LOG_CUTS files behind makes
     * a file longer, by at most the ring) */
    if (l->split > 0 && head + need - l->file_start >= (uint64_t)l->split) {
        uint64_t put = atomic_load_explicit(&l->cuts_put, memory_order_relaxed);
        if (put - atomic_load(&l->cuts_taken) < RT_LOG_CUTS) {
            l->file_start = head + need;
            atomic_store(&l->cuts[put % RT_LOG_CUTS], head + need);
            atomic_store(&l->cuts_put, put + 1);
        }
    }
    if (used + need >= l->cap / 8 && atomic_load(&l->sleeping)) sem_post(&l->wake);
    l->records++;
    return true;
}

bool rt_log_room(const rt_log *l)
{
    uint64_t head = atomic_load_explicit(&l->head, memory_order_relaxed);
    uint64_t tail = atomic_load_explicit(&l->tail, memory_order_acquire);
    return (size_t)(head - tail) <= l->cap / 2 ||
           atomic_load_explicit(&l->error, memory_order_relaxed) != 0;
}

void rt_log_get_stats(const rt_log *l, rt_log_stats *st)
{
    memset(st, 0, sizeof *st);
    st->records = l->records;
    st->bytes = (int64_t)atomic_load_explicit(&l->head, memory_order_relaxed);
    st->written = (int64_t)atomic_load_explicit(&l->tail, memory_order_acquire);
    st->dropped_full = l->dropped_full;
    st->dropped_in = l->dropped_in;
    st->dropped_failed = l->dropped_failed;
    st->too_large = l->too_large;
    st->error = atomic_load(&l->error);
    st->ring = l->cap;
    st->series = l->series;
    st->first = l->first;
    st->number = atomic_load(&l->number);
    st->files = atomic_load(&l->files);
    st->removed = atomic_load(&l->removed);
    st->removed_bytes = atomic_load(&l->removed_bytes);
    st->prune_error = atomic_load(&l->prune_error);
}

const char *rt_log_path(const rt_log *l) { return l->path; }

void rt_log_file(const rt_log *l, char *name, size_t n)
{
    if (!l->series || lag_out_series_name(l->path, atomic_load(&l->number), name, n) != 0)
        snprintf(name, n, "%s", l->path);
}
