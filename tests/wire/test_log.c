/*
 * Unit test of the bounded LCM log reader (server/wire/lagsim_log.c).
 *
 *   agreement   a log written by liblcm's own writer (lcm_eventlog_write_event) is read
 *               back record for record: channel, data, event number, timestamp, offset;
 *               from a regular file, from a pipe and from a memory stream;
 *   too large   a record above max_data is returned with data NULL and its size, and
 *               the next record is read (file and pipe);
 *   cut short   the same log cut at every byte: the complete records before the cut are
 *               returned, then the end, never an error;
 *   damage      junk before and between records, a flipped sync byte, a header whose
 *               lengths are absurd (0, 256, negative, 0x7fffffff): passed over, counted,
 *               every intact record still read;
 *   hopeless    LAG_LOG_SCAN_MAX + 1 bytes without a record, and /dev/zero: an error
 *               with a message; exactly LAG_LOG_SCAN_MAX bytes of junk still reads;
 *   open        a directory and a missing file are refused with a message.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <lcm/eventlog.h>

#include "lagsim_log.h"
#include "lagsim_test.h"

#define NREC 40
typedef struct ref {
    char channel[300];
    uint8_t data[3000];
    int32_t size;
    int64_t timestamp, offset;
} ref;
static ref refs[NREC];
static char path[256];
static uint8_t *image;   /* the log file's bytes */
static size_t image_len;

/* Writes the reference log with liblcm and keeps its bytes. */
static void write_reference(void)
{
    lcm_eventlog_t *w = lcm_eventlog_create(path, "w");
    if (!w) {
        perror(path);
        exit(1);
    }
    int64_t off = 0;
    for (int k = 0; k < NREC; k++) {
        ref *r = &refs[k];
        if (k == 7) memset(r->channel, 'C', 255), r->channel[255] = '\0'; /* longest */
        else snprintf(r->channel, sizeof r->channel, "CH_%d", k % 3);
        r->size = k == 3 ? 0 : (k * 73) % 2900 + 1;
        for (int i = 0; i < r->size; i++) r->data[i] = (uint8_t)(i * 31 + k);
        if (k == 11) memcpy(r->data, "\xED\xA1\xDA\x01", 4); /* a sync word inside data */
        r->timestamp = 1000000 * k + 7;
        r->offset = off;
        lcm_eventlog_event_t ev = {0, r->timestamp, (int32_t)strlen(r->channel), r->size,
                                   r->channel, r->data};
        ENSURE(lcm_eventlog_write_event(w, &ev) == 0);
        off += 28 + (int64_t)strlen(r->channel) + r->size;
    }
    lcm_eventlog_destroy(w);
    FILE *f = fopen(path, "rb");
    image = malloc((size_t)off);
    image_len = fread(image, 1, (size_t)off, f);
    fclose(f);
    ENSURE(image_len == (size_t)off);
}

/* Reads every record of lg; checks those it returns against refs[idx[..]]. Returns the
 * result of the last call. */
static int read_all(lag_log *lg, const int *idx, int n, size_t max_data, const char *what)
{
    lag_log_record rec;
    int got = 0, rc;
    while ((rc = lag_log_next(lg, &rec)) == LAG_LOG_OK) {
        if (got >= n) {
            ENSUREF(0, "%s: more records than %d", what, n);
            break;
        }
        const ref *r = &refs[idx[got]];
        ENSUREF(strcmp(rec.channel, r->channel) == 0, "%s: record %d channel %s", what, got,
                rec.channel);
        ENSUREF(rec.size == (size_t)r->size && rec.timestamp == r->timestamp,
                "%s: record %d size %zu", what, got, rec.size);
        if ((size_t)r->size <= max_data)
            ENSUREF(rec.data && memcmp(rec.data, r->data, (size_t)r->size) == 0,
                    "%s: record %d data", what, got);
        else
            ENSUREF(rec.data == NULL, "%s: record %d loaded above max_data", what, got);
        got++;
    }
    ENSUREF(got == n, "%s: %d records read, expected %d", what, got, n);
    return rc;
}

static int all[NREC];

static void check_agreement(void)
{
    char err[256];
    lag_log *lg = lag_log_open(path, 1 << 16, err, sizeof err);
    ENSURE(lg != NULL);
    lag_log_record rec;
    for (int k = 0; k < NREC; k++) {
        ENSURE(lag_log_next(lg, &rec) == LAG_LOG_OK);
        ENSURE(rec.event_number == k && rec.offset == refs[k].offset);
        ENSURE(strcmp(rec.channel, refs[k].channel) == 0 && rec.size == (size_t)refs[k].size);
        ENSURE(rec.size == 0 || memcmp(rec.data, refs[k].data, rec.size) == 0);
    }
    ENSURE(lag_log_next(lg, &rec) == LAG_LOG_END);
    ENSURE(lag_log_next(lg, &rec) == LAG_LOG_END); /* and stays so */
    lag_log_stats st;
    lag_log_get_stats(lg, &st);
    ENSURE(st.records == NREC && st.damaged == 0 && st.bytes_skipped == 0 &&
           st.truncated_bytes == 0 && st.too_large == 0);
    lag_log_close(lg);

    /* max_data below some records: those come back with data NULL */
    lg = lag_log_open(path, 1000, err, sizeof err);
    ENSURE(read_all(lg, all, NREC, 1000, "max_data 1000") == LAG_LOG_END);
    lag_log_get_stats(lg, &st);
    int large = 0;
    for (int k = 0; k < NREC; k++) large += refs[k].size > 1000;
    ENSURE(st.too_large == large && large > 5);
    lag_log_close(lg);

    /* a memory stream (no file descriptor) */
    FILE *m = fmemopen(image, image_len, "rb");
    lg = lag_log_open_stream(m, "memory", 1000, err, sizeof err);
    ENSUREF(lg != NULL, "%s", err);
    ENSURE(read_all(lg, all, NREC, 1000, "memory") == LAG_LOG_END);
    lag_log_close(lg);
    fclose(m);

    /* a pipe, fed by a child */
    int pfd[2];
    ENSURE(pipe(pfd) == 0);
    pid_t pid = fork();
    if (pid == 0) {
        close(pfd[0]);
        size_t done = 0;
        while (done < image_len) {
            ssize_t k = write(pfd[1], image + done, image_len - done < 777 ? image_len - done : 777);
            if (k <= 0) _exit(1);
            done += (size_t)k;
        }
        _exit(0);
    }
    close(pfd[1]);
    FILE *pf = fdopen(pfd[0], "rb");
    lg = lag_log_open_stream(pf, "pipe", 1000, err, sizeof err);
    ENSURE(read_all(lg, all, NREC, 1000, "pipe") == LAG_LOG_END);
    lag_log_close(lg);
    fclose(pf);
    waitpid(pid, NULL, 0);
}

/* Reads the bytes b[0..n) as a log from a file (regular) and from memory; from memory
 * only the first nidx_mem records when nidx_mem >= 0 (a stream has no size to check a
 * record's length against: a plausible but false length is read as a last record cut
 * short). */
static void read_bytes2(const uint8_t *b, size_t n, const int *idx, int nidx, int nidx_mem,
                        int expect_rc, lag_log_stats *st_file, const char *what);
static void read_bytes(const uint8_t *b, size_t n, const int *idx, int nidx, int expect_rc,
                       lag_log_stats *st_file, const char *what)
{
    read_bytes2(b, n, idx, nidx, -1, expect_rc, st_file, what);
}

static void read_bytes2(const uint8_t *b, size_t n, const int *idx, int nidx, int nidx_mem,
                        int expect_rc, lag_log_stats *st_file, const char *what)
{
    char err[256], name[300];
    FILE *f = fopen(path, "wb");
    fwrite(b, 1, n, f);
    fclose(f);
    lag_log *lg = lag_log_open(path, 1 << 16, err, sizeof err);
    snprintf(name, sizeof name, "%s (file)", what);
    ENSUREF(read_all(lg, idx, nidx, 1 << 16, name) == expect_rc, "%s", name);
    if (expect_rc == LAG_LOG_ERROR) ENSURE(strstr(lag_log_errmsg(lg), "not an LCM log") != NULL);
    lag_log_get_stats(lg, st_file);
    lag_log_close(lg);
    FILE *m = fmemopen((void *)b, n ? n : 1, "rb");
    if (n == 0) fgetc(m); /* fmemopen of 0 bytes is not allowed: an empty stream */
    lg = lag_log_open_stream(m, "memory", 1 << 16, err, sizeof err);
    snprintf(name, sizeof name, "%s (memory)", what);
    ENSUREF(read_all(lg, idx, nidx_mem >= 0 ? nidx_mem : nidx, 1 << 16, name) == expect_rc,
            "%s", name);
    lag_log_close(lg);
    fclose(m);
}

static void check_cut(void)
{
    /* the first three records, cut at every byte */
    size_t n3 = (size_t)refs[3].offset;
    for (size_t cut = 0; cut <= n3; cut++) {
        int complete = 0;
        while (complete < 3 && (size_t)refs[complete + 1].offset <= cut) complete++;
        lag_log_stats st;
        char what[64];
        snprintf(what, sizeof what, "cut at %zu", cut);
        read_bytes(image, cut, all, complete, LAG_LOG_END, &st, what);
        size_t rest = cut - (size_t)refs[complete].offset;
        ENSUREF(st.truncated_bytes + st.bytes_skipped == (int64_t)rest,
                "%s: %lld + %lld bytes, %zu left over", what, (long long)st.truncated_bytes,
                (long long)st.bytes_skipped, rest);
    }
}

static void check_damage(void)
{
    static uint8_t b[4 << 20];
    lag_log_stats st;
    /* junk before the first record and between records 4 and 5 */
    size_t p = 0;
    memcpy(b, "this is no log header!", 22);
    p = 22;
    memcpy(b + p, image, (size_t)refs[5].offset);
    p += (size_t)refs[5].offset;
    memset(b + p, 0xED, 9); /* near-sync bytes */
    p += 9;
    memcpy(b + p, image + refs[5].offset, image_len - (size_t)refs[5].offset);
    p += image_len - (size_t)refs[5].offset;
    read_bytes(b, p, all, NREC, LAG_LOG_END, &st, "junk");
    ENSURE(st.damaged == 2 && st.bytes_skipped == 31);

    /* a flipped sync byte: that record is lost, the others are read */
    memcpy(b, image, image_len);
    b[refs[9].offset + 2] ^= 0x10;
    int idx[NREC], n = 0;
    for (int k = 0; k < NREC; k++)
        if (k != 9) idx[n++] = k;
    read_bytes(b, image_len, idx, n, LAG_LOG_END, &st, "flipped sync");
    ENSURE(st.damaged == 1);

    /* absurd lengths in record 12's header: that record is lost, the rest read */
    struct {
        int at;
        uint32_t v;
    } bad[] = {{20, 0}, {20, 256}, {20, 0xffffffffu}, {24, 0xffffffffu}, {24, 0x7fffffffu},
               {24, 0x80000000u}};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; k++) {
        memcpy(b, image, image_len);
        uint8_t *h = b + refs[12].offset + bad[k].at;
        for (int i = 0; i < 4; i++) h[i] = (uint8_t)(bad[k].v >> (24 - 8 * i));
        n = 0;
        for (int j = 0; j < NREC; j++)
            if (j != 12) idx[n++] = j;
        char what[64];
        snprintf(what, sizeof what, "header byte %d = %#x", bad[k].at, bad[k].v);
        bool plausible = bad[k].at == 24 && bad[k].v == 0x7fffffffu;
        read_bytes2(b, image_len, idx, n, plausible ? 12 : -1, LAG_LOG_END, &st, what);
        ENSUREF(st.damaged == 1, "%s", what);
    }
    /* a channel with a NUL inside */
    memcpy(b, image, image_len);
    b[refs[13].offset + 28 + 1] = 0;
    n = 0;
    for (int j = 0; j < NREC; j++)
        if (j != 13) idx[n++] = j;
    read_bytes(b, image_len, idx, n, LAG_LOG_END, &st, "NUL in channel");

    /* the scan bound: exactly LAG_LOG_SCAN_MAX bytes of junk still read, one more not */
    memset(b, 0, LAG_LOG_SCAN_MAX + 1);
    memcpy(b + LAG_LOG_SCAN_MAX, image, image_len);
    read_bytes(b, LAG_LOG_SCAN_MAX + image_len, all, NREC, LAG_LOG_END, &st, "max junk");
    ENSURE(st.bytes_skipped == LAG_LOG_SCAN_MAX);
    memset(b, 0, LAG_LOG_SCAN_MAX + 1);
    memcpy(b + LAG_LOG_SCAN_MAX + 1, image, image_len);
    read_bytes(b, LAG_LOG_SCAN_MAX + 1 + image_len, all, 0, LAG_LOG_ERROR, &st, "too much junk");
    /* and between records: the bound counts from the last good record */
    memcpy(b, image, (size_t)refs[2].offset);
    memset(b + refs[2].offset, 'x', LAG_LOG_SCAN_MAX + 1);
    memcpy(b + refs[2].offset + LAG_LOG_SCAN_MAX + 1, image + refs[2].offset,
           image_len - (size_t)refs[2].offset);
    read_bytes(b, image_len + LAG_LOG_SCAN_MAX + 1, all, 2, LAG_LOG_ERROR, &st, "junk after 2");
    /* fake sync words back to back: no progress without bound */
    for (size_t i = 0; i + 4 <= (size_t)LAG_LOG_SCAN_MAX + 64; i += 4)
        memcpy(b + i, "\xED\xA1\xDA\x01", 4);
    read_bytes(b, (size_t)LAG_LOG_SCAN_MAX + 64, all, 0, LAG_LOG_ERROR, &st, "fake syncs");
}

static void check_open(void)
{
    char err[256];
    lag_log *lg = lag_log_open("/dev/zero", 1024, err, sizeof err);
    ENSURE(lg != NULL);
    lag_log_record rec;
    ENSURE(lag_log_next(lg, &rec) == LAG_LOG_ERROR);
    ENSURE(strstr(lag_log_errmsg(lg), "not an LCM log") != NULL);
    ENSURE(lag_log_next(lg, &rec) == LAG_LOG_ERROR);
    lag_log_close(lg);
    ENSURE(lag_log_open("/tmp", 1024, err, sizeof err) == NULL && strstr(err, "directory"));
    ENSURE(lag_log_open("/nonexistent/x.lcm", 1024, err, sizeof err) == NULL &&
           strstr(err, "cannot open"));
}

static void case_reader(int arg)
{
    (void)arg;
    snprintf(path, sizeof path, "/tmp/lagsim_test_log_%d.lcm", (int)getpid());
    for (int k = 0; k < NREC; k++) all[k] = k;
    write_reference();
    check_agreement();
    check_cut();
    check_damage();
    check_open();
    remove(path);
    free(image);
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {{"reader", case_reader, 0, 0}};
    return lt_main(argc, argv, cases, 1);
}
