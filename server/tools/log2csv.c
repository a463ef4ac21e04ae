/*
 * lagsim-log2csv's conversion (see log2csv.h).
 *
 * One pass over the log. Each channel takes the lagsim type of its first decodable
 * message; its CSV is opened then, with a header from that message (a state's joint
 * names). A later message of another type or other joints on the same channel is not
 * written, only counted. Every number is written as the shortest decimal that reads
 * back to the same double (lagsim_num.h); every string from the log (names, kinds,
 * details, in headers and cells) is quoted only where RFC 4180 needs it and kept from
 * reading as a spreadsheet formula (put_text). A state sent again unchanged (the state at
 * t = 0 while the plant waits for its first command, a paused state: the same generation,
 * step, sim time and numbers) is one row; the copies are counted in the summary.
 *
 * Per-channel facts for the summary: counts, log-time span and rate, undecodable
 * messages; for states the step sequence (gaps: a step increase other than one control
 * period, with the states missing; resets: the step going back; copies: the same state
 * again, not written; repeats: the same step again with other numbers, written); for
 * status the last counters; for events a count per kind.
 */
#include "log2csv.h"
#include "lagsim_num.h"
#include "lagsim/lagsim.h"

#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "lagsim_bus.h"
#include "lagsim_out.h"

#define L2C_MAX_CHANNELS 256
#define L2C_MAX_KINDS 48
#define L2C_NAME LAG_WIRE_NAME_LEN
#define L2C_JOINTS LAG_WIRE_MAX_JOINTS
#define L2C_NONE (-1)               /* a channel's type before a lagsim message decodes */

typedef struct chan {
    char name[LAG_LOG_CHANNEL_MAX + 1];
    int type;                   /* lag_wire_type, or L2C_NONE */
    bool selected;
    FILE *csv;
    int64_t messages, rows, undecodable, mismatched;
    int64_t first_ts, last_ts;
    /* states */
    int nj;
    char joint[L2C_JOINTS][L2C_NAME];
    bool have_prev;
    int64_t prev_step, first_step, last_step;
    int64_t period_ticks;       /* 0 = unknown yet */
    bool period_from_scene;
    int64_t gaps, missing, resets, repeats, copies;
    lag_wire_joint_state last; /* the state of the last row (copies are not written) */
    double first_sim, last_sim;
    /* status */
    lag_wire_status last_status;
    bool have_status;
    /* events */
    int n_kinds;
    char kind[L2C_MAX_KINDS][L2C_NAME];
    int64_t kind_count[L2C_MAX_KINDS];
    int64_t kinds_other;
    /* scenes: ticks per control period of the latest one */
    int64_t scene_period_ticks;
} chan;

typedef struct l2c {
    const l2c_opts *o;
    chan *ch;
    int n_ch, cap_ch;
    FILE *discard;              /* /dev/null, shared by every channel when outdir is NULL */
    int64_t untracked;          /* messages on channels beyond L2C_MAX_CHANNELS */
    char used[L2C_MAX_CHANNELS][LAG_LOG_CHANNEL_MAX + 24]; /* CSV file names taken */
    int n_used;
    char *err;
    size_t errlen;
    bool write_failed;
} l2c;

/* ---------------------------------------------------------------- CSV helpers */
static void put_d(FILE *f, double x)
{
    char b[LAG_NUM_LEN];
    fprintf(f, ",%s", lag_num(x, b));
}
/* A row's first number: its sim time. */
static void put_t(FILE *f, double t)
{
    char b[LAG_NUM_LEN];
    fputs(lag_num(t, b), f);
}
static void put_i(FILE *f, int64_t x) { fprintf(f, ",%" PRId64, x); }
/* One text field from a log (a name, a kind, a detail), RFC 4180: control characters
 * become spaces, so one record is one line; in double quotes (a quote doubled) only when
 * it holds a comma or a quote, as RFC 4180 needs, so that a plain name reads as itself
 * everywhere (Octave's importdata keeps quotes it is given: "theta"). A field whose
 * first non-blank character would start a formula in a spreadsheet (=, +, -, @; tab and
 * CR are spaces by then) is written as text: a leading apostrophe, as OWASP's
 * CSV-injection guidance asks (the apostrophe needs no quotes). `suffix` (may be NULL) is
 * appended to it: a header's "<joint>_dot". Numbers never pass here: they stay numbers. */
static void put_text(FILE *f, const char *s, const char *suffix)
{
    const char *p = s;
    while (*p == ' ' || *p == 0x7f || ((unsigned char)*p < 0x20 && *p)) p++; /* all blank out */
    bool formula = *p == '=' || *p == '+' || *p == '-' || *p == '@';
    const char *sfx = suffix ? suffix : "";
    bool quote = strpbrk(s, ",\"") || strpbrk(sfx, ",\""); /* CR and LF are spaces by now */
    if (quote) fputc('"', f);
    if (formula) fputc('\'', f);
    for (int pass = 0; pass < 2; pass++)
        for (const char *q = pass ? sfx : s; *q; q++) {
            unsigned char c = (unsigned char)*q;
            if (c == '"') fputs("\"\"", f);
            else if (c < 0x20 || c == 0x7f) fputc(' ', f);
            else fputc(c, f);
        }
    if (quote) fputc('"', f);
}
static void put_s(FILE *f, const char *s)
{
    fputc(',', f);
    put_text(f, s, NULL);
}
/* A list of numbers this tool formatted (lag_num's, joined by spaces): no comma or quote,
 * so no quotes, and not marked as text, a leading minus sign included (digits, signs, '.',
 * 'e', "inf", "nan" and spaces make no formula that reaches anything). */
static void put_numbers(FILE *f, const char *s) { fprintf(f, ",%s", s); }
/* Log timestamp and utime in seconds since the epoch (us resolution). */
static void put_us(FILE *f, int64_t us, bool first)
{
    /* exact: integer seconds and microseconds, no rounding through a double */
    int64_t s = us / 1000000, r = us % 1000000;
    if (r < 0) {
        r += 1000000;
        s -= 1;
    }
    fprintf(f, "%s%" PRId64 ".%06" PRId64, first ? "" : ",", s, r);
}

/* A channel name as a file name: [A-Za-z0-9_.-], no leading dot, unique. */
static void file_name(l2c *c, const char *channel, char *out, size_t cap)
{
    char base[LAG_LOG_CHANNEL_MAX + 1];
    size_t n = 0;
    for (const char *p = channel; *p && n + 1 < sizeof base; p++) {
        char k = *p;
        bool ok = (k >= 'A' && k <= 'Z') || (k >= 'a' && k <= 'z') || (k >= '0' && k <= '9') ||
                  k == '_' || k == '-' || (k == '.' && n > 0);
        base[n++] = ok ? k : '_';
    }
    base[n] = '\0';
    for (int k = 1;; k++) {
        if (k == 1) snprintf(out, cap, "%s.csv", base);
        else snprintf(out, cap, "%s.%d.csv", base, k);
        bool taken = false;
        for (int i = 0; i < c->n_used && !taken; i++) taken = strcmp(c->used[i], out) == 0;
        if (!taken) break;
    }
    if (c->n_used < L2C_MAX_CHANNELS) {
        snprintf(c->used[c->n_used], sizeof c->used[0], "%s", out);
        c->n_used++;
    }
}

static FILE *open_csv(l2c *c, chan *h)
{
    FILE *f;
    if (!c->o->outdir) {
        if (!c->discard && !(c->discard = fopen("/dev/null", "w"))) {
            snprintf(c->err, c->errlen, "cannot open /dev/null: %s", strerror(errno));
            c->write_failed = true;
        }
        return c->discard;
    } else {
        char fname[LAG_LOG_CHANNEL_MAX + 24], path[4096];
        file_name(c, h->name, fname, sizeof fname);
        snprintf(path, sizeof path, "%s/%s", c->o->outdir, fname);
        /* never through a symbolic link, never over the log read, nor over an existing
         * file without --force (lagsim_out.h) */
        const char *inputs[1] = {c->o->input};
        char oerr[512];
        int fd = lag_out_open("cannot write", path, c->o->force, inputs, 1, 0, oerr, sizeof oerr);
        f = fd >= 0 ? fdopen(fd, "w") : NULL;
        if (!f) {
            if (fd >= 0) {
                snprintf(oerr, sizeof oerr, "cannot write %.400s: %s", path, strerror(errno));
                close(fd);
            }
            snprintf(c->err, c->errlen, "%s", oerr);
            c->write_failed = true;
            return NULL;
        }
        if (c->o->listing)
            fprintf(c->o->listing, "%s  (%s, %s)\n", path, h->name,
                    lag_wire_type_name((lag_wire_type)h->type));
    }
    return f;
}

/* ---------------------------------------------------------------- channels */
static chan *find_chan(l2c *c, const char *name)
{
    for (int i = 0; i < c->n_ch; i++)
        if (strcmp(c->ch[i].name, name) == 0) return &c->ch[i];
    if (c->n_ch >= L2C_MAX_CHANNELS) return NULL;
    if (c->n_ch == c->cap_ch) {
        int cap = c->cap_ch ? 2 * c->cap_ch : 8;
        chan *nc = realloc(c->ch, (size_t)cap * sizeof *nc);
        if (!nc) return NULL;
        c->ch = nc;
        c->cap_ch = cap;
    }
    chan *h = &c->ch[c->n_ch++];
    memset(h, 0, sizeof *h);
    snprintf(h->name, sizeof h->name, "%s", name);
    h->type = L2C_NONE;
    h->selected = c->o->n_select == 0;
    for (int i = 0; i < c->o->n_select; i++)
        if (strcmp(c->o->select[i], name) == 0) h->selected = true;
    return h;
}

/* The scene channel that goes with a state channel: "<PREFIX>_STATE" -> "<PREFIX>_SCENE". */
static chan *scene_of(l2c *c, const chan *state)
{
    const char *st = lag_bus_suffix(LAG_BUS_STATE);
    size_t n = strlen(state->name), k = strlen(st);
    if (n < k || strcmp(state->name + n - k, st) != 0) return NULL;
    char prefix[LAG_LOG_CHANNEL_MAX + 1], name[LAG_LOG_CHANNEL_MAX + 1];
    snprintf(prefix, sizeof prefix, "%.*s", (int)(n - k), state->name);
    lag_bus_channel_name(name, sizeof name, prefix, LAG_BUS_SCENE);
    for (int i = 0; i < c->n_ch; i++)
        if (strcmp(c->ch[i].name, name) == 0) return &c->ch[i];
    return NULL;
}

/* ---------------------------------------------------------------- one type each */
static void header_state(FILE *f, const lag_wire_joint_state *m)
{
    static const char *const suffix[] = {"", "_dot", "_effort"};
    fputs("t,wall_time,log_time,step,generation", f);
    for (int k = 0; k < 3; k++)
        for (int i = 0; i < m->num_joints; i++) {
            fputc(',', f);
            put_text(f, m->name[i], suffix[k]);
        }
    fputc('\n', f);
}

/* Whether m is the state of the last row sent again: the same generation, step, sim time
 * and numbers (the daemon publishes the state it waits at anew while it waits). */
static bool is_copy(const chan *h, const lag_wire_joint_state *m)
{
    const lag_wire_joint_state *l = &h->last;
    size_t n = (size_t)m->num_joints * sizeof(double);
    return h->have_prev && m->generation == l->generation && m->step == l->step &&
           !memcmp(&m->sim_time, &l->sim_time, sizeof m->sim_time) &&
           m->num_joints == l->num_joints && !memcmp(m->position, l->position, n) &&
           !memcmp(m->velocity, l->velocity, n) && !memcmp(m->effort, l->effort, n);
}

/* Step bookkeeping of a state channel (gaps, resets, repeats). */
static void track_steps(l2c *c, chan *h, const lag_wire_joint_state *m)
{
    chan *sc = scene_of(c, h);
    if (sc && sc->scene_period_ticks > 0) {
        h->period_ticks = sc->scene_period_ticks;
        h->period_from_scene = true;
    }
    if (!h->have_prev) {
        h->first_step = m->step;
        h->first_sim = m->sim_time;
    } else {
        /* differences of hostile steps may overflow: compare before subtracting */
        if (m->step < h->prev_step) {
            h->resets++;
        } else if (m->step == h->prev_step) {
            h->repeats++;
        } else {
            uint64_t d = (uint64_t)m->step - (uint64_t)h->prev_step;
            if (h->period_ticks == 0) h->period_ticks = d > INT64_MAX ? INT64_MAX : (int64_t)d;
            uint64_t p = (uint64_t)h->period_ticks;
            if (d != p) {
                h->gaps++;
                if (d > p && d % p == 0) {
                    uint64_t miss = d / p - 1;
                    h->missing = (uint64_t)h->missing + miss > INT64_MAX ? INT64_MAX
                                                                       : h->missing + (int64_t)miss;
                }
            }
        }
    }
    h->have_prev = true;
    h->prev_step = m->step;
    h->last_step = m->step;
    h->last_sim = m->sim_time;
}

static bool write_state(l2c *c, chan *h, const lag_log_record *r, const lag_wire_joint_state *m)
{
    if (!h->csv) {
        h->nj = m->num_joints;
        for (int i = 0; i < m->num_joints; i++) snprintf(h->joint[i], L2C_NAME, "%s", m->name[i]);
        if (!(h->csv = open_csv(c, h))) return false;
        header_state(h->csv, m);
    }
    bool same = m->num_joints == h->nj;
    for (int i = 0; same && i < h->nj; i++) same = strcmp(m->name[i], h->joint[i]) == 0;
    if (!same) {
        h->mismatched++;
        return true;
    }
    if (is_copy(h, m)) { /* one row per state: the copy counted, not written */
        h->copies++;
        return true;
    }
    track_steps(c, h, m);
    h->last = *m;
    FILE *f = h->csv;
    put_t(f, m->sim_time);
    put_us(f, m->utime, false);
    put_us(f, r->timestamp, false);
    put_i(f, m->step);
    put_i(f, m->generation);
    for (int i = 0; i < m->num_joints; i++) put_d(f, m->position[i]);
    for (int i = 0; i < m->num_joints; i++) put_d(f, m->velocity[i]);
    for (int i = 0; i < m->num_joints; i++) put_d(f, m->effort[i]);
    fputc('\n', f);
    return true;
}

/* A reference: t, times, step, then r, r' and r'' under the state CSV's names (<joint>,
 * <joint>_dot; r'': <joint>_ddot), so that a row of the two files with the same t pairs q
 * with r. */
static bool write_reference(l2c *c, chan *h, const lag_log_record *r,
                            const lag_wire_reference *m)
{
    if (!h->csv) {
        h->nj = m->num_joints;
        for (int i = 0; i < m->num_joints; i++) snprintf(h->joint[i], L2C_NAME, "%s", m->name[i]);
        if (!(h->csv = open_csv(c, h))) return false;
        fputs("t,wall_time,log_time,step,generation", h->csv);
        for (int k = 0; k < 3; k++)
            for (int i = 0; i < m->num_joints; i++) {
                fputc(',', h->csv);
                put_text(h->csv, m->name[i], k == 2 ? "_ddot" : k ? "_dot" : "");
            }
        fputc('\n', h->csv);
    }
    bool same = m->num_joints == h->nj;
    for (int i = 0; same && i < h->nj; i++) same = strcmp(m->name[i], h->joint[i]) == 0;
    if (!same) {
        h->mismatched++;
        return true;
    }
    FILE *f = h->csv;
    put_t(f, m->sim_time);
    put_us(f, m->utime, false);
    put_us(f, r->timestamp, false);
    put_i(f, m->step);
    put_i(f, m->generation);
    for (int i = 0; i < m->num_joints; i++) put_d(f, m->r[i]);
    for (int i = 0; i < m->num_joints; i++) put_d(f, m->rdot[i]);
    for (int i = 0; i < m->num_joints; i++) put_d(f, m->rddot[i]);
    fputc('\n', f);
    return true;
}

/* The status CSV's columns: t (sim time), wall_time (the daemon's utime), log_time, then
 * every other field of status_t in its order, from the codec's table (a field added to
 * the type is a column without anyone listing it); the daemon's own wall_time field is
 * daemon_wall_time, a boolean is 0 or 1. */
static bool status_column(const lag_wire_field *fd)
{
    return fd->count_field < 0 && strcmp(fd->name, "utime") && strcmp(fd->name, "sim_time");
}

static bool write_status(l2c *c, chan *h, const lag_log_record *r, const lag_wire_status *m)
{
    int n = 0;
    const lag_wire_field *fd = lag_wire_fields(LAG_WIRE_STATUS, &n);
    if (!h->csv) {
        if (!(h->csv = open_csv(c, h))) return false;
        fputs("t,wall_time,log_time", h->csv);
        for (int i = 0; i < n; i++)
            if (status_column(&fd[i]))
                fprintf(h->csv, ",%s", strcmp(fd[i].name, "wall_time") ? fd[i].name : "daemon_wall_time");
        fputc('\n', h->csv);
    }
    FILE *f = h->csv;
    put_t(f, m->sim_time);
    put_us(f, m->utime, false);
    put_us(f, r->timestamp, false);
    for (int i = 0; i < n; i++) {
        if (!status_column(&fd[i])) continue;
        const char *p = (const char *)m + fd[i].offset;
        switch (fd[i].kind) {
        case LAG_WIRE_INT8: put_i(f, *(const int8_t *)p); break;
        case LAG_WIRE_INT16: put_i(f, *(const int16_t *)p); break;
        case LAG_WIRE_INT64: put_i(f, *(const int64_t *)p); break;
        case LAG_WIRE_DOUBLE: put_d(f, *(const double *)p); break;
        case LAG_WIRE_BOOLEAN: put_i(f, *(const bool *)p ? 1 : 0); break;
        case LAG_WIRE_STRING: put_s(f, p); break;
        }
    }
    fputc('\n', f);
    h->last_status = *m;
    h->have_status = true;
    return true;
}

static bool write_event(l2c *c, chan *h, const lag_log_record *r, const lag_wire_event *m)
{
    if (!h->csv) {
        if (!(h->csv = open_csv(c, h))) return false;
        fputs("t,wall_time,log_time,step,kind,joint,value,detail\n", h->csv);
    }
    FILE *f = h->csv;
    put_t(f, m->sim_time);
    put_us(f, m->utime, false);
    put_us(f, r->timestamp, false);
    put_i(f, m->step);
    put_s(f, m->kind);
    put_s(f, m->joint);
    put_d(f, m->value);
    put_s(f, m->detail);
    fputc('\n', f);
    int k = 0;
    while (k < h->n_kinds && strcmp(h->kind[k], m->kind) != 0) k++;
    if (k == h->n_kinds && k < L2C_MAX_KINDS) {
        snprintf(h->kind[k], L2C_NAME, "%s", m->kind);
        h->kind_count[k] = 0;
        h->n_kinds++;
    }
    if (k < h->n_kinds) h->kind_count[k]++;
    else h->kinds_other++;
    return true;
}

/* The core's model whose joints are the scene's (lag_model_info_by_joints), or NULL: where
 * a joint's unit (m or rad) comes from. */
static const lag_model_info *scene_model(const lag_wire_scene *m)
{
    const char *names[LAG_WIRE_MAX_JOINTS];
    int n = m->num_joints < 0 ? 0 : m->num_joints > LAG_WIRE_MAX_JOINTS ? LAG_WIRE_MAX_JOINTS
                                                                        : m->num_joints;
    for (int i = 0; i < n; i++) names[i] = m->joint_name[i];
    return n == m->num_joints ? lag_model_info_by_joints(names, n) : NULL;
}

static bool write_scene(l2c *c, chan *h, const lag_log_record *r, const lag_wire_scene *m)
{
    if (!h->csv) {
        if (!(h->csv = open_csv(c, h))) return false;
        fputs("wall_time,log_time,model,prefix,dt,control_period,integrator,mode,rate,"
              "command_timeout,effects,parameters,joints,generation\n", h->csv);
    }
    FILE *f = h->csv;
    char params[LAG_WIRE_MAX_PARAMS * (L2C_NAME + 32)], joints[L2C_JOINTS * (L2C_NAME + 192)];
    char a[LAG_NUM_LEN], b[LAG_NUM_LEN];
    size_t n = 0;
    params[0] = joints[0] = '\0';
    const lag_model_info *info = scene_model(m);
    for (int i = 0; i < m->num_params; i++)
        n += (size_t)snprintf(params + n, sizeof params - n, "%s%s=%s", i ? " " : "",
                              m->param_name[i], lag_num(m->param_value[i], a));
    n = 0;
    for (int i = 0; i < m->num_joints; i++) {
        n += (size_t)snprintf(joints + n, sizeof joints - n, "%s%s:%s:q0=%s:qd0=%s",
                              i ? " " : "", m->joint_name[i],
                              m->actuated[i] ? "actuated" : "free", lag_num(m->initial_q[i], a),
                              lag_num(m->initial_qd[i], b));
        if (m->limit_on[i])
            n += (size_t)snprintf(joints + n, sizeof joints - n, ":limits=%s..%s",
                                  lag_num(m->limit_lower[i], a), lag_num(m->limit_upper[i], b));
        if (info)
            n += (size_t)snprintf(joints + n, sizeof joints - n, ":unit=%s",
                                  info->angular[i] ? "rad" : "m");
    }
    put_us(f, m->utime, true);
    put_us(f, r->timestamp, false);
    put_s(f, m->model);
    put_s(f, m->prefix);
    put_d(f, m->dt);
    put_d(f, m->control_period);
    put_s(f, m->integrator);
    put_s(f, m->mode);
    put_d(f, m->rate);
    put_d(f, m->command_timeout);
    put_s(f, m->effects);
    put_s(f, params);
    put_s(f, joints);
    put_i(f, m->generation);
    fputc('\n', f);
    return true;
}

static bool write_command(l2c *c, chan *h, const lag_log_record *r,
                          const lag_wire_joint_command *m)
{
    if (!h->csv) {
        if (!(h->csv = open_csv(c, h))) return false;
        fputs("t,wall_time,log_time,generation,joint,effort\n", h->csv);
    }
    FILE *f = h->csv;
    /* one row per named joint (a command with no joint: one row, joint and effort empty) */
    for (int i = 0; i < (m->num_joints > 0 ? m->num_joints : 1); i++) {
        put_t(f, m->sim_time);
        put_us(f, m->utime, false);
        put_us(f, r->timestamp, false);
        put_i(f, m->generation);
        if (m->num_joints > 0) {
            put_s(f, m->name[i]);
            put_d(f, m->effort[i]);
        } else {
            fputs(",,", f);
        }
        fputc('\n', f);
    }
    return true;
}

/* control_t's requests by their constants (lag_wire_request_name), in lower case */
static const char *request_name(int r, char *buf, size_t len)
{
    const char *n = lag_wire_request_name(r);
    size_t k = 0;
    for (; n && n[k] && k + 1 < len; k++) buf[k] = (char)(n[k] >= 'A' && n[k] <= 'Z' ? n[k] + 32 : n[k]);
    buf[k] = '\0';
    return n ? buf : "unknown";
}

static bool write_control(l2c *c, chan *h, const lag_log_record *r, const lag_wire_control *m)
{
    if (!h->csv) {
        if (!(h->csv = open_csv(c, h))) return false;
        fputs("wall_time,log_time,request,name,count,q,qd,key,value\n", h->csv);
    }
    FILE *f = h->csv;
    char q[L2C_JOINTS * 26] = "", qd[L2C_JOINTS * 26] = "";
    size_t nq = 0, nqd = 0;
    for (int i = 0; i < m->num_joints; i++) {
        char a[LAG_NUM_LEN];
        nq += (size_t)snprintf(q + nq, sizeof q - nq, "%s%s", i ? " " : "", lag_num(m->q[i], a));
        nqd += (size_t)snprintf(qd + nqd, sizeof qd - nqd, "%s%s", i ? " " : "",
                                lag_num(m->qd[i], a));
    }
    put_us(f, m->utime, true);
    put_us(f, r->timestamp, false);
    put_i(f, m->request);
    char name[32];
    put_s(f, request_name(m->request, name, sizeof name));
    put_i(f, m->count);
    put_numbers(f, q);
    put_numbers(f, qd);
    put_s(f, m->key);   /* SET: what it changes */
    put_s(f, m->value);
    fputc('\n', f);
    return true;
}

/* Ticks per control period of a scene: a whole number of its ticks (lag_ticks_exact), as
 * the daemon writes it; 0 if it makes no sense. */
static int64_t period_ticks(const lag_wire_scene *m)
{
    int64_t k;
    return m->dt > 0 && lag_ticks_exact(m->control_period, m->dt, &k) && k >= 1 &&
                   k < 1000000000000000LL
               ? k
               : 0;
}

/* One record: decode as the channel's type (the first that decodes fixes it). */
static bool record(l2c *c, const lag_log_record *r)
{
    chan *h = find_chan(c, r->channel);
    if (!h) {
        c->untracked++;
        return true;
    }
    h->messages++;
    if (h->messages == 1) h->first_ts = r->timestamp;
    h->last_ts = r->timestamp;
    if (!r->data) { /* larger than any lagsim message: not one */
        if (h->type != L2C_NONE) h->undecodable++;
        return true;
    }
    int t = lag_wire_identify_any(r->data, r->size, NULL); /* any version (wire.md) */
    if (h->type == L2C_NONE) {
        if (t < 0) return true; /* not lagsim's (yet): counted as other */
        h->type = t;
    }
    if (t != h->type) {
        h->undecodable++;
        return true;
    }
    if (!h->selected && t != LAG_WIRE_SCENE) return true; /* scenes always: they give periods */
    union {
        lag_wire_joint_state st;
        lag_wire_status ss;
        lag_wire_event ev;
        lag_wire_scene sc;
        lag_wire_joint_command cm;
        lag_wire_control ct;
        lag_wire_reference rf;
    } m;
    int d = lag_wire_decode_any((lag_wire_type)t, r->data, r->size, LAG_WIRE_MAX_JOINTS, &m,
                                NULL);
    /* an event's over-long detail is kept, cut (the rest of the event decoded) */
    if (d == LAG_WIRE_ETOOLONG && t == LAG_WIRE_EVENT) d = LAG_WIRE_OK;
    if (d != LAG_WIRE_OK) {
        h->undecodable++;
        return true;
    }
    bool ok = true;
    switch ((lag_wire_type)t) {
    case LAG_WIRE_JOINT_STATE: ok = write_state(c, h, r, &m.st); break;
    case LAG_WIRE_STATUS: ok = write_status(c, h, r, &m.ss); break;
    case LAG_WIRE_EVENT: ok = write_event(c, h, r, &m.ev); break;
    case LAG_WIRE_SCENE:
        h->scene_period_ticks = period_ticks(&m.sc);
        if (h->selected) ok = write_scene(c, h, r, &m.sc);
        break;
    case LAG_WIRE_JOINT_COMMAND: ok = write_command(c, h, r, &m.cm); break;
    case LAG_WIRE_CONTROL: ok = write_control(c, h, r, &m.ct); break;
    case LAG_WIRE_REFERENCE: ok = write_reference(c, h, r, &m.rf); break;
    default: break;
    }
    if (h->selected) h->rows++;
    return ok;
}

/* ---------------------------------------------------------------- summary */
/* The last status of a status channel: its run state and counters. */
static void summarize_status(const lag_wire_status *s, FILE *f)
{
    /* counters from the bus: summed in unsigned arithmetic (a hostile sum wraps,
     * it does not overflow) */
    int64_t rej = (int64_t)((uint64_t)s->rejected_unknown_joint +
                            (uint64_t)s->rejected_unactuated +
                            (uint64_t)s->rejected_nonfinite +
                            (uint64_t)s->rejected_bad_length +
                            (uint64_t)s->rejected_undecodable +
                            (uint64_t)s->rejected_stale);
    fprintf(f, "  last: run state %s, commands accepted %" PRId64
               ", rejected %" PRId64 " (unknown joint %" PRId64
               ", unactuated %" PRId64 ", non-finite %" PRId64
               ", bad length %" PRId64 ", undecodable %" PRId64 ", stale %" PRId64
               "), controls rejected %" PRId64 ", watchdog trips %" PRId64
               ", lockstep timeouts %" PRId64 ", numeric faults %" PRId64
               ", overruns %" PRId64 ", states published %" PRId64 "\n",
            s->run_state, s->commands_accepted, rej, s->rejected_unknown_joint,
            s->rejected_unactuated, s->rejected_nonfinite, s->rejected_bad_length,
            s->rejected_undecodable, s->rejected_stale, s->controls_rejected,
            s->watchdog_trips, s->lockstep_timeouts, s->numeric_faults,
            s->overruns, s->states_published);
}

static void summarize(l2c *c, const lag_log_stats *ls, FILE *f)
{
    fprintf(f, "records: %" PRId64 " (%" PRId64 " larger than %d bytes passed over; %" PRId64
               " damaged places, %" PRId64 " bytes skipped; last record cut short by %" PRId64
               " bytes)\n",
            ls->records, ls->too_large, L2C_MAX_DATA, ls->damaged, ls->bytes_skipped,
            ls->truncated_bytes);
    int other = 0;
    for (int i = 0; i < c->n_ch; i++) {
        chan *h = &c->ch[i];
        if (h->type == L2C_NONE) {
            other++;
            continue;
        }
        if (!h->selected) continue;
        double span = ((double)h->last_ts - (double)h->first_ts) * 1e-6; /* hostile: no int overflow */
        fprintf(f, "%s: %s, %" PRId64 " messages", h->name,
                lag_wire_type_name((lag_wire_type)h->type), h->messages);
        if (h->messages > 1 && span > 0)
            fprintf(f, " over %.3f s of log time (%.4g /s)", span, (double)(h->messages - 1) / span);
        if (h->undecodable) fprintf(f, ", %" PRId64 " undecodable", h->undecodable);
        if (h->mismatched) fprintf(f, ", %" PRId64 " with other joints (not written)", h->mismatched);
        fputc('\n', f);
        switch ((lag_wire_type)h->type) {
        case LAG_WIRE_JOINT_STATE:
            if (h->have_prev)
                fprintf(f, "  sim time %.9g .. %.9g s, step %" PRId64 " .. %" PRId64
                           "; gaps %" PRId64 " (%" PRId64 " states missing; period %" PRId64
                           " ticks%s), resets %" PRId64 ", repeats %" PRId64 "; copies %"
                           PRId64 " (a state sent again unchanged: one row)\n",
                        h->first_sim, h->last_sim, h->first_step, h->last_step, h->gaps,
                        h->missing, h->period_ticks,
                        h->period_from_scene ? ", from the scene" : ", inferred",
                        h->resets, h->repeats, h->copies);
            break;
        case LAG_WIRE_STATUS:
            if (h->have_status) summarize_status(&h->last_status, f);
            break;
        case LAG_WIRE_EVENT:
            fputs("  events:", f);
            for (int k = 0; k < h->n_kinds; k++)
                fprintf(f, " %s %" PRId64, h->kind[k], h->kind_count[k]);
            if (h->kinds_other) fprintf(f, " (other kinds %" PRId64 ")", h->kinds_other);
            fputc('\n', f);
            break;
        default:
            break;
        }
    }
    if (other) {
        fprintf(f, "other channels (not lagsim's):");
        for (int i = 0; i < c->n_ch; i++)
            if (c->ch[i].type == L2C_NONE)
                fprintf(f, " %s (%" PRId64 ")", c->ch[i].name, c->ch[i].messages);
        fputc('\n', f);
    }
    if (c->untracked)
        fprintf(f, "messages on channels beyond the first %d: %" PRId64 "\n", L2C_MAX_CHANNELS,
                c->untracked);
}

lag_result l2c_convert(lag_log *lg, const l2c_opts *o, FILE *summary, char *err, size_t errlen)
{
    l2c c;
    memset(&c, 0, sizeof c);
    c.o = o;
    c.err = err;
    c.errlen = errlen;
    lag_result rc = LAG_OK;
    lag_log_record r;
    int got;
    while ((got = lag_log_next(lg, &r)) == LAG_LOG_OK) {
        if (!record(&c, &r)) {
            rc = LAG_ERR_FILE;
            break;
        }
    }
    lag_log_stats ls;
    lag_log_get_stats(lg, &ls);
    if (got == LAG_LOG_ERROR) {
        snprintf(err, errlen, "%s", lag_log_errmsg(lg));
        rc = LAG_ERR_RUNTIME;
    } else if (rc == LAG_OK && ls.records == 0 && (ls.damaged > 0 || ls.truncated_bytes > 0)) {
        /* bytes, and not one whole record among them */
        snprintf(err, errlen, "no complete LCM log record in its %lld bytes: not an LCM log",
                 (long long)(ls.bytes_skipped + ls.truncated_bytes));
        rc = LAG_ERR_RUNTIME;
    }
    for (int i = 0; i < c.n_ch; i++)
        if (c.ch[i].csv && c.ch[i].csv != c.discard) {
            if (ferror(c.ch[i].csv) || fclose(c.ch[i].csv) != 0) {
                if (rc == LAG_OK) {
                    snprintf(err, errlen, "write error on the CSV of %s", c.ch[i].name);
                    rc = LAG_ERR_FILE;
                }
            }
            c.ch[i].csv = NULL;
        }
    if (summary) summarize(&c, &ls, summary);
    if (c.discard) fclose(c.discard);
    free(c.ch);
    return rc;
}
