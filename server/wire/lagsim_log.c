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

/* One search for the next record: lag_log_next's steps share it. */
typedef struct log_search {
    lag_log *lg;
    lag_log_record *rec;
    int64_t searched;  /* bytes passed over since the last good record */
    int64_t suspect;   /* offset of a header that did not fit in the file, or -1 */
    bool damaged;      /* the sequence of records was lost on the way */
    int64_t off;       /* offset of the sync word found */
    uint8_t h[HEADER + LAG_LOG_CHANNEL_MAX]; /* the header after it, and the channel */
    int nread;         /* bytes of h read */
    int64_t evnum, stamp, chan_len, data_len;
} log_search;

/* A step's result besides lag_log_next's own (LAG_LOG_OK, _END, _ERROR). */
enum { STEP_ON = 2, STEP_NOT_A_RECORD = 3 };

/* The end inside a record: the bytes passed over before it are skipped, and the last
 * `cut` bytes are the record cut short. */
static int end_in_record(log_search *s, int64_t cut)
{
    s->lg->st.bytes_skipped += s->searched;
    if (s->damaged) s->lg->st.damaged++;
    return at_end(s->lg, cut);
}

/* Reads up to and including the next sync word: STEP_ON, or the end, or an error. */
static int find_sync(log_search *s)
{
    lag_log *lg = s->lg;
    uint32_t w = 0;
    int64_t have = 0;
    for (;;) {
        int c = src_getc(lg);
        if (c < 0) {
            /* the end inside the search: what was passed over is junk, unless it follows
             * a header that did not fit (a last record cut short) */
            int64_t junk = s->searched + have;
            int64_t cut = s->suspect >= 0 ? lg->pos - s->suspect : 0;
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
        if (s->searched + have - 3 > LAG_LOG_SCAN_MAX) return too_far(lg, s->searched + have);
    }
    s->searched += have - 4;
    if (have > 4) s->damaged = true;
    s->off = lg->pos - 4;
    return STEP_ON;
}

/* Reads the header after the sync word and the channel: STEP_ON when they make a record
 * that fits, STEP_NOT_A_RECORD when not, or the end. */
static int read_header(log_search *s)
{
    lag_log *lg = s->lg;
    size_t got = src_read(lg, s->h, HEADER);
    if (got < HEADER) return end_in_record(s, 4 + (int64_t)got);
    s->evnum = be(s->h, 8);
    s->stamp = be(s->h + 8, 8);
    s->chan_len = be(s->h + 16, 4);
    s->data_len = be(s->h + 20, 4);
    bool ok = s->chan_len >= 1 && s->chan_len <= LAG_LOG_CHANNEL_MAX && s->data_len >= 0;
    if (ok && lg->regular && s->chan_len + s->data_len > src_left(lg)) {
        ok = false;
        if (s->suspect < 0) s->suspect = s->off;
    }
    s->nread = HEADER;
    if (ok) {
        got = src_read(lg, s->h + HEADER, (size_t)s->chan_len);
        s->nread += (int)got;
        if (got < (size_t)s->chan_len) return end_in_record(s, 4 + s->nread);
        ok = memchr(s->h + HEADER, 0, (size_t)s->chan_len) == NULL;
    }
    return ok ? STEP_ON : STEP_NOT_A_RECORD;
}

/* Not a record: search again from the byte after this sync word (the sync word cannot
 * overlap itself, so none starts inside it). STEP_ON, or an error. */
static int search_again(log_search *s)
{
    src_unread(s->lg, s->h, s->nread);
    s->searched += 4;
    s->damaged = true;
    if (s->searched > LAG_LOG_SCAN_MAX) return too_far(s->lg, s->searched);
    return STEP_ON;
}

/* Reads the record's data (passed over when larger than max_data) and fills the record:
 * LAG_LOG_OK, or the end. */
static int read_data(log_search *s)
{
    lag_log *lg = s->lg;
    lag_log_record *rec = s->rec;
    size_t got;
    if ((size_t)s->data_len <= lg->max_data) {
        got = src_read(lg, lg->data, (size_t)s->data_len);
        rec->data = lg->data;
    } else {
        got = src_read(lg, NULL, (size_t)s->data_len);
        rec->data = NULL;
        lg->st.too_large++;
    }
    if (got < (size_t)s->data_len) {
        memset(rec, 0, sizeof *rec);
        return end_in_record(s, 4 + s->nread + (int64_t)got);
    }
    rec->offset = s->off;
    rec->event_number = s->evnum;
    rec->timestamp = s->stamp;
    memcpy(rec->channel, s->h + HEADER, (size_t)s->chan_len);
    rec->channel[s->chan_len] = '\0';
    rec->size = (size_t)s->data_len;
    lg->st.records++;
    lg->st.bytes_skipped += s->searched;
    if (s->damaged) lg->st.damaged++;
    return LAG_LOG_OK;
}

int lag_log_next(lag_log *lg, lag_log_record *rec)
{
    memset(rec, 0, sizeof *rec);
    if (!lg) return LAG_LOG_ERROR;
    if (lg->state != LAG_LOG_OK) return lg->state;
    log_search s = {.lg = lg, .rec = rec, .suspect = -1};
    for (;;) {
        int r = find_sync(&s);
        if (r == STEP_ON) r = read_header(&s);
        if (r == STEP_NOT_A_RECORD) r = search_again(&s);
        else if (r == STEP_ON) return read_data(&s);
        if (r != STEP_ON) return r;
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
