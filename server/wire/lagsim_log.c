/*
 * A bounded reader of LCM log files: see lagsim_log.h.
 *
 * Bytes come through a small source with a push-back stack, so that a header found to
 * be bogus can be searched again from the byte after its sync word on any stream (a pipe
 * included), and every byte is read once from the file.
 */
#include "lagsim_log.h"

#include <errno.h>
#include <stdarg.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

#define SYNC LAG_LOG_SYNC
#define HEADER (LAG_LOG_HEADER_SIZE - 4)            /* after the sync word */
#define PUSHBACK (HEADER + LAG_LOG_CHANNEL_MAX)     /* most bytes ever pushed back */

struct lag_log {
    FILE *f;
    bool own;                 /* opened here: closed by lag_log_close */
    bool regular;             /* a regular file: its size bounds every record */
    char name[256];
    int64_t pos;              /* offset of the next byte */
    uint8_t back[PUSHBACK];   /* pushed-back bytes; back[nback - 1] is read next */
    int nback;
    uint8_t *data;
    size_t max_data;
    int state;                /* LAG_LOG_OK while reading, then END or ERROR for good */
    lag_log_stats st;
    char errmsg[320];
};

static void set_err(lag_log *lg, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void set_err(lag_log *lg, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(lg->errmsg, sizeof lg->errmsg, fmt, ap);
    va_end(ap);
    lg->state = LAG_LOG_ERROR;
}

/* ---------------------------------------------------------------- byte source */
/* The next byte, or -1 at the end of the stream (or on a read error: see ferror). */
static int src_getc(lag_log *lg)
{
    int c;
    if (lg->nback > 0) c = lg->back[--lg->nback];
    else c = getc(lg->f);
    if (c == EOF) return -1;
    lg->pos++;
    return c;
}

/* Pushes b[0..n) back so that b[0] is read next. */
static void src_unread(lag_log *lg, const uint8_t *b, int n)
{
    for (int i = n - 1; i >= 0; i--) lg->back[lg->nback++] = b[i];
    lg->pos -= n;
}

/* Reads up to n bytes into buf (NULL: discard them); returns how many. */
static size_t src_read(lag_log *lg, uint8_t *buf, size_t n)
{
    size_t got = 0;
    while (got < n && lg->nback > 0) {
        uint8_t c = lg->back[--lg->nback];
        if (buf) buf[got] = c;
        got++;
    }
    if (buf) {
        got += fread(buf + got, 1, n - got, lg->f);
    } else if (got < n && lg->regular) {
        /* the caller checked that the file holds these bytes */
        off_t here = ftello(lg->f);
        if (here >= 0 && fseeko(lg->f, (off_t)(n - got), SEEK_CUR) == 0) got = n;
        else if (here >= 0) fseeko(lg->f, here, SEEK_SET);
    }
    while (got < n && !buf) {
        uint8_t scratch[4096];
        size_t want = n - got < sizeof scratch ? n - got : sizeof scratch;
        size_t r = fread(scratch, 1, want, lg->f);
        got += r;
        if (r < want) break;
    }
    lg->pos += (int64_t)got;
    return got;
}

/* Bytes of the file from the current position to its end (regular files only). */
static int64_t src_left(lag_log *lg)
{
    struct stat sb;
    if (fstat(fileno(lg->f), &sb) != 0) return INT64_MAX;
    return (int64_t)sb.st_size - lg->pos;
}

/* ---------------------------------------------------------------- open / close */
static lag_log *log_new(FILE *f, bool own, const char *name, size_t max_data, char *err,
                        size_t errlen)
{
    if (err && errlen) err[0] = '\0';
    struct stat sb;
    memset(&sb, 0, sizeof sb); /* a stream without a descriptor (fmemopen): not regular */
    if (fileno(f) >= 0 && fstat(fileno(f), &sb) != 0) {
        if (err) snprintf(err, errlen, "%s: %s", name, strerror(errno));
        return NULL;
    }
    if (S_ISDIR(sb.st_mode)) {
        if (err) snprintf(err, errlen, "%s: is a directory, not an LCM log", name);
        return NULL;
    }
    if (max_data > LAG_LOG_DATA_MAX) max_data = LAG_LOG_DATA_MAX;
    lag_log *lg = calloc(1, sizeof *lg);
    uint8_t *data = malloc(max_data ? max_data : 1);
    if (!lg || !data) {
        free(lg);
        free(data);
        if (err) snprintf(err, errlen, "%s: out of memory", name);
        return NULL;
    }
    lg->f = f;
    lg->own = own;
    lg->regular = S_ISREG(sb.st_mode);
    snprintf(lg->name, sizeof lg->name, "%s", name);
    lg->pos = 0;
    lg->data = data;
    lg->max_data = max_data;
    lg->state = LAG_LOG_OK;
    if (lg->regular) {
        off_t here = ftello(f);
        if (here > 0) lg->pos = (int64_t)here;
    }
    return lg;
}

lag_log *lag_log_open(const char *path, size_t max_data, char *err, size_t errlen)
{
    FILE *f = fopen(path, "rb");
    if (!f) {
        if (err) snprintf(err, errlen, "cannot open %s: %s", path, strerror(errno));
        return NULL;
    }
    lag_log *lg = log_new(f, true, path, max_data, err, errlen);
    if (!lg) fclose(f);
    return lg;
}

lag_log *lag_log_open_stream(FILE *f, const char *name, size_t max_data, char *err,
                             size_t errlen)
{
    if (!f) {
        if (err) snprintf(err, errlen, "no stream");
        return NULL;
    }
    return log_new(f, false, name ? name : "log", max_data, err, errlen);
}

void lag_log_close(lag_log *lg)
{
    if (!lg) return;
    if (lg->own) fclose(lg->f);
    free(lg->data);
    free(lg);
}

const char *lag_log_errmsg(const lag_log *lg) { return lg ? lg->errmsg : "no log"; }

void lag_log_get_stats(const lag_log *lg, lag_log_stats *st) { *st = lg->st; }

/* ---------------------------------------------------------------- records */
static int64_t be(const uint8_t *b, int n)
{
    uint64_t v = 0;
    for (int i = 0; i < n; i++) v = (v << 8) | b[i];
    if (n == 4) return (int32_t)(uint32_t)v;
    return (int64_t)v;
}

/* The end of the stream: a read error, or the end of the log, whose last `cut` bytes
 * are a record cut short. */
static int at_end(lag_log *lg, int64_t cut)
{
    if (ferror(lg->f)) {
        set_err(lg, "%s: read error at byte %lld: %s", lg->name, (long long)lg->pos,
                strerror(errno));
        return LAG_LOG_ERROR;
    }
    lg->st.truncated_bytes += cut;
    lg->state = LAG_LOG_END;
    return LAG_LOG_END;
}

/* More than LAG_LOG_SCAN_MAX bytes passed over since the last record (which ended
 * `searched` bytes ago): the log is hopeless. */
static int too_far(lag_log *lg, int64_t searched)
{
    set_err(lg, "%s: no LCM log record in the %d bytes after byte %lld: not an LCM log, or "
                "damaged beyond repair",
            lg->name, LAG_LOG_SCAN_MAX, (long long)(lg->pos - searched));
    return LAG_LOG_ERROR;
}

int lag_log_next(lag_log *lg, lag_log_record *rec)
{
    memset(rec, 0, sizeof *rec);
    if (!lg) return LAG_LOG_ERROR;
    if (lg->state != LAG_LOG_OK) return lg->state;

    int64_t searched = 0;       /* bytes passed over since the last good record */
    int64_t suspect = -1;       /* offset of a header that did not fit in the file */
    bool damaged = false;
    for (;;) {
        /* the sync word */
        uint32_t w = 0;
        int64_t have = 0;
        for (;;) {
            int c = src_getc(lg);
            if (c < 0) {
                /* the end inside the search: what was passed over is junk, unless it
                 * follows a header that did not fit (a last record cut short) */
                int64_t junk = searched + have;
                int64_t cut = suspect >= 0 ? lg->pos - suspect : 0;
                if (junk > cut) {
                    lg->st.bytes_skipped += junk - cut;
                    lg->st.damaged++;
                }
                return at_end(lg, cut);
            }
            w = (w << 8) | (uint32_t)c;
            have++;
            if (have >= 4 && w == SYNC) break;
            /* all but the last 3 bytes read cannot start a sync word any more */
            if (searched + have - 3 > LAG_LOG_SCAN_MAX) return too_far(lg, searched + have);
        }
        searched += have - 4;
        if (have > 4) damaged = true;
        int64_t off = lg->pos - 4;

        /* the header */
        uint8_t h[HEADER + LAG_LOG_CHANNEL_MAX];
        size_t got = src_read(lg, h, HEADER);
        if (got < HEADER) {
            lg->st.bytes_skipped += searched;
            if (damaged) lg->st.damaged++;
            return at_end(lg, 4 + (int64_t)got);
        }
        int64_t evnum = be(h, 8), stamp = be(h + 8, 8);
        int64_t chan_len = be(h + 16, 4), data_len = be(h + 20, 4);
        bool ok = chan_len >= 1 && chan_len <= LAG_LOG_CHANNEL_MAX && data_len >= 0;
        if (ok && lg->regular && chan_len + data_len > src_left(lg)) {
            ok = false;
            if (suspect < 0) suspect = off;
        }
        int nread = HEADER;
        if (ok) {
            got = src_read(lg, h + HEADER, (size_t)chan_len);
            nread += (int)got;
            if (got < (size_t)chan_len) {
                lg->st.bytes_skipped += searched;
                if (damaged) lg->st.damaged++;
                return at_end(lg, 4 + nread);
            }
            ok = memchr(h + HEADER, 0, (size_t)chan_len) == NULL;
        }
        if (!ok) {
            /* not a record: search again from the byte after this sync word (the sync
             * word cannot overlap itself, so none starts inside it) */
            src_unread(lg, h, nread);
            searched += 4;
            damaged = true;
            if (searched > LAG_LOG_SCAN_MAX) return too_far(lg, searched);
            continue;
        }

        /* the data */
        if ((size_t)data_len <= lg->max_data) {
            got = src_read(lg, lg->data, (size_t)data_len);
            rec->data = lg->data;
        } else {
            got = src_read(lg, NULL, (size_t)data_len);
            rec->data = NULL;
            lg->st.too_large++;
        }
        if (got < (size_t)data_len) {
            memset(rec, 0, sizeof *rec);
            lg->st.bytes_skipped += searched;
            if (damaged) lg->st.damaged++;
            return at_end(lg, 4 + nread + (int64_t)got);
        }
        rec->offset = off;
        rec->event_number = evnum;
        rec->timestamp = stamp;
        memcpy(rec->channel, h + HEADER, (size_t)chan_len);
        rec->channel[chan_len] = '\0';
        rec->size = (size_t)data_len;
        lg->st.records++;
        lg->st.bytes_skipped += searched;
        if (damaged) lg->st.damaged++;
        return LAG_LOG_OK;
    }
}

/* ---------------------------------------------------------------- writing */
static void put_be(uint8_t *b, uint64_t v, int n)
{
    for (int i = n - 1; i >= 0; i--) {
        b[i] = (uint8_t)(v & 0xff);
        v >>= 8;
    }
}

void lag_log_put_header(uint8_t out[LAG_LOG_HEADER_SIZE], int64_t event_number,
                        int64_t timestamp, int32_t channel_len, int32_t data_len)
{
    put_be(out, SYNC, 4);
    put_be(out + 4, (uint64_t)event_number, 8);
    put_be(out + 12, (uint64_t)timestamp, 8);
    put_be(out + 20, (uint32_t)channel_len, 4);
    put_be(out + 24, (uint32_t)data_len, 4);
}
