/*
 * A bounded reader of LCM log files (what lcm-logger writes; what lagsimd --replay and the
 * log tools read).
 *
 * The format (LCM's "log file format"): records back to back, each
 *     uint32 sync word 0xEDA1DA01, int64 event number, int64 timestamp (us),
 *     int32 channel length, int32 data length, channel bytes (no NUL), data bytes,
 * every integer big-endian. liblcm's reader trusts the two lengths (a data length of
 * 0x7fffffff overflows its allocation and crashes) and searches for a sync word without
 * end (`/dev/zero` never returns). This one:
 *   - checks each header before trusting it: channel length 1..LAG_LOG_CHANNEL_MAX, data
 *     length >= 0, channel without NUL, and, for a regular file, the record inside the
 *     file; a header that fails is treated as damage: the reader searches on from the
 *     byte after its sync word;
 *   - searches at most LAG_LOG_SCAN_MAX bytes for the next record after the last good one:
 *     past that the log is hopeless (LAG_LOG_ERROR with a message);
 *   - loads a record's data only up to the max_data given at open (one buffer allocated
 *     then, nothing after); a larger record is passed over and returned with data NULL;
 *   - ends cleanly on a last record cut short (a logger stopped while writing), counting
 *     its bytes in lag_log_stats.truncated_bytes.
 * On a stream that is not a regular file (a pipe), a record cannot be checked against the
 * file's size: a damaged but plausible data length is read as a last record cut short.
 */
#ifndef LAGSIM_LOG_H
#define LAGSIM_LOG_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#ifdef __cplusplus
extern "C" {
#endif

#define LAG_LOG_CHANNEL_MAX 255        /* longest channel name accepted, bytes */
#define LAG_LOG_SCAN_MAX (1 << 20)     /* bytes searched for a record before giving up */
#define LAG_LOG_DATA_MAX (1 << 28)     /* largest max_data accepted at open */
#define LAG_LOG_SYNC 0xEDA1DA01u       /* each record starts with this word */
#define LAG_LOG_HEADER_SIZE 28         /* sync word and the four fields before the channel */

/* Results: 0 a record, 1 the end, negative an error (message: lag_log_errmsg). */
enum { LAG_LOG_OK = 0, LAG_LOG_END = 1, LAG_LOG_ERROR = -1 };

typedef struct lag_log_record {
    int64_t offset;                        /* byte offset of the record's sync word */
    int64_t event_number;
    int64_t timestamp;                     /* us (lcm-logger: when it received it) */
    char channel[LAG_LOG_CHANNEL_MAX + 1];
    const uint8_t *data;                   /* valid until the next call; NULL when size >
                                            * the reader's max_data (not loaded) */
    size_t size;                           /* bytes of data */
} lag_log_record;

typedef struct lag_log_stats {
    int64_t records;          /* returned by lag_log_next */
    int64_t too_large;        /* of which returned with data NULL */
    int64_t damaged;          /* places where the reader lost the sequence of records */
    int64_t bytes_skipped;    /* bytes passed over to find the next record */
    int64_t truncated_bytes;  /* bytes of a last record cut short by the end of the file */
} lag_log_stats;

typedef struct lag_log lag_log;

/* Opens path for reading; max_data: largest record data loaded (at most LAG_LOG_DATA_MAX).
 * Returns NULL with a message in err on failure. */
lag_log *lag_log_open(const char *path, size_t max_data, char *err, size_t errlen);
/* The same on a stream the caller keeps (not closed by lag_log_close); name is used in
 * messages. */
lag_log *lag_log_open_stream(FILE *f, const char *name, size_t max_data, char *err,
                             size_t errlen);
/* The next record: LAG_LOG_OK (rec filled), LAG_LOG_END, or LAG_LOG_ERROR. After END or
 * ERROR every further call returns the same. OUT: rec */
int lag_log_next(lag_log *lg, lag_log_record *rec);
/* Message of the error ("" if none). */
const char *lag_log_errmsg(const lag_log *lg);
void lag_log_get_stats(const lag_log *lg, lag_log_stats *st);
void lag_log_close(lag_log *lg);

/* The writer's side: the header of one record (sync word, event number, timestamp in us,
 * channel length, data length; big-endian), to be followed by the channel's bytes (no
 * NUL) and the data. OUT: out */
void lag_log_put_header(uint8_t out[LAG_LOG_HEADER_SIZE], int64_t event_number,
                        int64_t timestamp, int32_t channel_len, int32_t data_len);

#ifdef __cplusplus
}
#endif
#endif
