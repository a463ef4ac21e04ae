/*
 * Fuzz target: the bounded LCM log reader on arbitrary bytes (a memory stream, so no
 * file is written), and the wire decoder on every record of a lagsim state channel.
 *
 * Reading must end (LAG_LOG_END or LAG_LOG_ERROR) without crashing or leaking; every
 * record returned must lie inside the input, after the previous one, with a channel of
 * 1 to 255 bytes without NUL and its data either loaded (at most max_data bytes) or
 * reported too large; the counts of the statistics must add up to at most the input.
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim_log.h"
#include "lagsim_wire.h"

static void fail(const char *what)
{
    fprintf(stderr, "fuzz_log: %s\n", what);
    abort();
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size == 0) return 0; /* fmemopen needs a byte */
    FILE *f = fmemopen((void *)data, size, "rb");
    if (!f) return 0;
    char err[256];
    const size_t max_data = 512;
    lag_log *lg = lag_log_open_stream(f, "fuzz", max_data, err, sizeof err);
    if (!lg) fail(err);
    lag_log_record rec;
    int rc;
    int64_t last_end = 0, bytes = 0, records = 0;
    while ((rc = lag_log_next(lg, &rec)) == LAG_LOG_OK) {
        size_t clen = strlen(rec.channel);
        if (clen < 1 || clen > LAG_LOG_CHANNEL_MAX) fail("channel length");
        if (rec.offset < last_end) fail("records overlap");
        int64_t end = rec.offset + 28 + (int64_t)clen + (int64_t)rec.size;
        if (end > (int64_t)size) fail("record beyond the input");
        if (rec.data && rec.size > max_data) fail("loaded above max_data");
        if (!rec.data && rec.size <= max_data) fail("not loaded below max_data");
        if (rec.data && memcmp(rec.data, data + end - (int64_t)rec.size, rec.size) != 0)
            fail("data differs from the input");
        last_end = end;
        bytes += 28 + (int64_t)clen + (int64_t)rec.size;
        records++;
        if (rec.data && !strcmp(rec.channel, "DIPC_STATE")) {
            lag_wire_joint_state st;
            lag_wire_decode_joint_state(rec.data, rec.size, LAG_WIRE_MAX_JOINTS, &st);
        }
    }
    if (rc != LAG_LOG_END && rc != LAG_LOG_ERROR) fail("bad result");
    if (lag_log_next(lg, &rec) != rc) fail("the end did not last");
    lag_log_stats st;
    lag_log_get_stats(lg, &st);
    if (st.records != records) fail("records counted");
    if (bytes + st.bytes_skipped + st.truncated_bytes > (int64_t)size) fail("bytes counted");
    if (rc == LAG_LOG_END && bytes + st.bytes_skipped + st.truncated_bytes != (int64_t)size)
        fail("bytes unaccounted at the end");
    lag_log_close(lg);
    fclose(f);
    return 0;
}
