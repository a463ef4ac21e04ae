/*
 * lagsimd --log FILE: an LCM log written beside the real-time loop without ever making it
 * wait on the disk.
 *
 * The loop (one producer) copies each record, already in the LCM log format (header,
 * channel, data: lagsim_log.h), into a ring of bytes allocated once at open; a writer
 * thread (one consumer) writes what the ring holds to the file with writev(2) and frees
 * the space. Neither side takes a lock: two atomic counters (bytes put, bytes written)
 * and a semaphore that wakes the writer when it sleeps on an empty ring.
 *
 * A put never blocks. When the record does not fit, it is not written and it is counted:
 *   - what the daemon publishes (RT_LOG_OUT) may fill the ring;
 *   - what it receives (RT_LOG_IN: commands, control requests) only up to 3/4 of it, so
 *     that a flood on the input channels cannot push the states out of the log;
 *   - a record larger than 1/4 of the ring is never written (too_large).
 * The loop asks rt_log_room() before a period of the modes that have no wall-clock
 * deadline (fast, lockstep) and holds that period while the ring is more than half
 * full: those runs slow down to the disk's pace instead of losing records. In realtime
 * mode the loop never waits: a disk slower than the run loses records, counted.
 *
 * A series (--increment) goes on in its next file when the one being written holds
 * `split` bytes (--split-mb): the loop marks the end of the record that crossed it, the
 * writer writes up to that mark, opens the next file (lagsim_out.h's series), removes the
 * series' oldest beyond `keep`, and goes on; each file is an LCM log on its own, its
 * records numbered on from the previous one's.
 *
 * A write that fails (a full disk: ENOSPC; a FIFO whose reader left: EPIPE; a file-size
 * limit: EFBIG; the next file of a series that cannot be made) stops the writer for good; from then on every put is refused and counted (dropped_failed) and
 * rt_log_stats.error holds the errno. The writer uses write(2), not stdio, so that a
 * stalled device can be abandoned at close (the thread is cancelled) without exit()
 * flushing into it.
 */
#ifndef LAGSIMD_RT_LOG_H
#define LAGSIMD_RT_LOG_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define RT_LOG_RING_DEFAULT (16u << 20)   /* bytes: 16 MiB */
#define RT_LOG_RING_MIN (256u << 10)      /* bytes: 256 KiB */
#define RT_LOG_RING_MAX (1024u << 20)     /* bytes: 1 GiB */

typedef enum rt_log_dir { RT_LOG_OUT = 0, RT_LOG_IN } rt_log_dir;

typedef struct rt_log rt_log;

typedef struct rt_log_stats {
    int64_t records;         /* records put (and numbered) */
    int64_t bytes;           /* bytes put */
    int64_t written;         /* bytes the writer has written to the file */
    int64_t dropped_full;    /* published messages not written: the ring was full */
    int64_t dropped_in;      /* received messages not written: the ring was 3/4 full */
    int64_t dropped_failed;  /* records refused after a write error */
    int64_t too_large;       /* records larger than a quarter of the ring */
    int error;               /* errno of the write that failed, 0 if none */
    size_t ring;             /* the ring's size, bytes */
    /* a series (--increment): the numbers of the first and of the current file, files
     * begun (1 + splits), the older files --keep removed and their bytes, and the errno
     * of the last removal that failed (0 if none: a failed removal stops nothing) */
    bool series;
    uint64_t first, number;
    int64_t files, removed, removed_bytes;
    int prune_error;
} rt_log_stats;

/* What --log asks for. */
typedef struct rt_log_conf {
    const char *path;     /* --log FILE */
    size_t ring;          /* bytes between the loop and the writer, clamped to
                           * [RT_LOG_RING_MIN, RT_LOG_RING_MAX] */
    bool force;           /* --force: an existing regular FILE may be replaced */
    bool series;          /* --increment: FILE.000000, FILE.000001, ... (lagsim_out.h's
                           * series: the next number at open) instead of FILE */
    int keep;             /* --keep N (series): at each new file, the series' N newest kept
                           * and the older removed; 0: none removed */
    int64_t split;        /* --split-mb (series): bytes after which the writer goes on in the
                           * next file of the series, at a record's end; 0: never */
    const char *input;    /* the scene file: never written */
} rt_log_conf;

/* Opens the log by lag_out_open's rules (lagsim_out.h: a symbolic link, the scene file
 * and, without force, an existing regular file are refused), or the series' next file
 * (then --keep's removals are made), allocates the ring and starts the writer thread,
 * which inherits the caller's signal mask. Opening never blocks (a FIFO without a reader
 * is an error). Returns NULL with a message in err on failure; *refused (may be NULL)
 * tells a refusal by the rules (a usage error) from a failure of the system. */
rt_log *rt_log_open(const rt_log_conf *c, bool *refused, char *err, size_t errlen);
/* Puts one record (timestamp in us) in the ring; false when it was not, counted in the
 * stats by reason. Never blocks, never allocates. The producer's only call besides
 * rt_log_room and rt_log_get_stats. */
bool rt_log_put(rt_log *l, rt_log_dir dir, int64_t timestamp_us, const char *channel,
                const void *data, size_t len);
/* True when a period may start in a mode without deadlines: the ring is at most half
 * full, or the writer has failed (holding would then be for ever). */
bool rt_log_room(const rt_log *l);
/* The counters so far. OUT: st */
void rt_log_get_stats(const rt_log *l, rt_log_stats *st);
/* The path given at open (--log FILE). */
const char *rt_log_path(const rt_log *l);
/* The file being written: the path, or the series' current file. OUT: name */
void rt_log_file(const rt_log *l, char *name, size_t n);
/* Lets the writer write everything put so far, waiting as long as it makes progress; a
 * writer that makes none for stall_ms is cancelled and what it held is lost. Closes the
 * file and frees l (NULL: nothing). Returns 0 when every record put reached the file,
 * -1 otherwise. OUT: final (may be NULL): the last counters */
int rt_log_close(rt_log *l, int stall_ms, rt_log_stats *final);

#endif
