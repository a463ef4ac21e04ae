/*
 * Bounded encoding and decoding of lagsim's LCM messages: see lagsim_wire.h.
 *
 * LCM's format (lcm-gen's C and Java output, LCM's type specification): a message is its
 * 8-byte fingerprint, then its fields in declaration order, big-endian; a string is an
 * int32 length that counts the final NUL, then that many bytes; a boolean is one byte; a
 * variable-length array is its elements back to back, its count being an earlier field.
 */
#include "lagsim_wire.h"

#include <math.h>
#include <string.h>

#include "lagsim/lagsim_control_t.h"
#include "lagsim/lagsim_event_t.h"
#include "lagsim/lagsim_joint_command_t.h"
#include "lagsim/lagsim_joint_state_t.h"
#include "lagsim/lagsim_reference_t.h"
#include "lagsim/lagsim_scene_t.h"
#include "lagsim/lagsim_status_t.h"

/* ---------------------------------------------------------------- tables */
#define MEMBER_SIZE(T, m) sizeof(((T *)0)->m)
#define ELEM_SIZE(T, m) sizeof(((T *)0)->m[0])
#define NELEM(T, m) ((int)(MEMBER_SIZE(T, m) / ELEM_SIZE(T, m)))

/* A scalar of kind K. */
#define SCALAR(T, K, m) {#m, K, -1, 0, false, MEMBER_SIZE(T, m), offsetof(T, m)}
/* A string field. */
#define STRING(T, m) {#m, LAG_WIRE_STRING, -1, 0, false, MEMBER_SIZE(T, m), offsetof(T, m)}
/* An int16 count bounded by cap (and by max_joints when J). */
#define COUNT(T, m, cap, J) {#m, LAG_WIRE_INT16, -1, cap, J, MEMBER_SIZE(T, m), offsetof(T, m)}
/* An array of kind K whose count is field number c of the table. */
#define ARRAY(T, K, m, c) {#m, K, c, NELEM(T, m), false, ELEM_SIZE(T, m), offsetof(T, m)}

typedef lag_wire_joint_state JS;
static const lag_wire_field joint_state_fields[] = {
    SCALAR(JS, LAG_WIRE_INT64, utime),
    SCALAR(JS, LAG_WIRE_DOUBLE, sim_time),
    SCALAR(JS, LAG_WIRE_INT64, step),
    COUNT(JS, num_joints, LAG_WIRE_MAX_JOINTS, true),           /* 3 */
    ARRAY(JS, LAG_WIRE_STRING, name, 3),
    ARRAY(JS, LAG_WIRE_DOUBLE, position, 3),
    ARRAY(JS, LAG_WIRE_DOUBLE, velocity, 3),
    ARRAY(JS, LAG_WIRE_DOUBLE, effort, 3),
    SCALAR(JS, LAG_WIRE_INT64, generation),                     /* 0.2.0 */
};

typedef lag_wire_reference RF;
static const lag_wire_field reference_fields[] = {
    SCALAR(RF, LAG_WIRE_INT64, utime),
    SCALAR(RF, LAG_WIRE_DOUBLE, sim_time),
    SCALAR(RF, LAG_WIRE_INT64, step),
    COUNT(RF, num_joints, LAG_WIRE_MAX_JOINTS, true),           /* 3 */
    ARRAY(RF, LAG_WIRE_STRING, name, 3),
    ARRAY(RF, LAG_WIRE_DOUBLE, r, 3),
    ARRAY(RF, LAG_WIRE_DOUBLE, rdot, 3),
    SCALAR(RF, LAG_WIRE_INT64, generation),                     /* 0.2.0 */
    ARRAY(RF, LAG_WIRE_DOUBLE, rddot, 3),                       /* 0.2.0 */
};

typedef lag_wire_joint_command JC;
static const lag_wire_field joint_command_fields[] = {
    SCALAR(JC, LAG_WIRE_INT64, utime),
    SCALAR(JC, LAG_WIRE_DOUBLE, sim_time),
    COUNT(JC, num_joints, LAG_WIRE_MAX_JOINTS, true),           /* 2 */
    ARRAY(JC, LAG_WIRE_STRING, name, 2),
    ARRAY(JC, LAG_WIRE_DOUBLE, effort, 2),
    SCALAR(JC, LAG_WIRE_INT64, generation),                     /* 0.2.0 */
};

typedef lag_wire_control CT;
static const lag_wire_field control_fields[] = {
    SCALAR(CT, LAG_WIRE_INT64, utime),
    SCALAR(CT, LAG_WIRE_INT8, request),
    SCALAR(CT, LAG_WIRE_INT64, count),
    COUNT(CT, num_joints, LAG_WIRE_MAX_JOINTS, true),           /* 3 */
    ARRAY(CT, LAG_WIRE_DOUBLE, q, 3),
    ARRAY(CT, LAG_WIRE_DOUBLE, qd, 3),
    STRING(CT, key),
    STRING(CT, value),
};

typedef lag_wire_event EV;
static const lag_wire_field event_fields[] = {
    SCALAR(EV, LAG_WIRE_INT64, utime),
    SCALAR(EV, LAG_WIRE_DOUBLE, sim_time),
    SCALAR(EV, LAG_WIRE_INT64, step),
    STRING(EV, kind),
    STRING(EV, joint),
    SCALAR(EV, LAG_WIRE_DOUBLE, value),
    STRING(EV, detail),
};

typedef lag_wire_status ST;
static const lag_wire_field status_fields[] = {
    SCALAR(ST, LAG_WIRE_INT64, utime),
    SCALAR(ST, LAG_WIRE_DOUBLE, sim_time),
    SCALAR(ST, LAG_WIRE_INT64, step),
    SCALAR(ST, LAG_WIRE_DOUBLE, wall_time),
    SCALAR(ST, LAG_WIRE_DOUBLE, rtf),
    SCALAR(ST, LAG_WIRE_INT64, overruns),
    SCALAR(ST, LAG_WIRE_DOUBLE, step_time_max_us),
    SCALAR(ST, LAG_WIRE_DOUBLE, step_time_mean_us),
    SCALAR(ST, LAG_WIRE_DOUBLE, energy),
    STRING(ST, integrator),
    STRING(ST, mode),
    STRING(ST, run_state),
    SCALAR(ST, LAG_WIRE_INT64, commands_accepted),
    SCALAR(ST, LAG_WIRE_INT64, rejected_unknown_joint),
    SCALAR(ST, LAG_WIRE_INT64, rejected_unactuated),
    SCALAR(ST, LAG_WIRE_INT64, rejected_nonfinite),
    SCALAR(ST, LAG_WIRE_INT64, rejected_bad_length),
    SCALAR(ST, LAG_WIRE_INT64, rejected_undecodable),
    SCALAR(ST, LAG_WIRE_INT64, controls_rejected),
    SCALAR(ST, LAG_WIRE_BOOLEAN, watchdog_tripped),
    SCALAR(ST, LAG_WIRE_INT64, watchdog_trips),
    SCALAR(ST, LAG_WIRE_INT64, lockstep_timeouts),
    SCALAR(ST, LAG_WIRE_INT64, numeric_faults),
    SCALAR(ST, LAG_WIRE_INT64, rejected_stale),
    SCALAR(ST, LAG_WIRE_INT64, overrun_bursts),
    SCALAR(ST, LAG_WIRE_INT64, states_published),
    SCALAR(ST, LAG_WIRE_INT64, rejected_effort_limit),
    SCALAR(ST, LAG_WIRE_INT64, lockstep_retries),
    SCALAR(ST, LAG_WIRE_INT64, commands_ignored),
    STRING(ST, contact),
    SCALAR(ST, LAG_WIRE_INT64, plant_conflicts),
    STRING(ST, waiting_for),
    SCALAR(ST, LAG_WIRE_DOUBLE, waiting_s),
    STRING(ST, waiting_got),
    SCALAR(ST, LAG_WIRE_INT64, commands_wrong_port),
    SCALAR(ST, LAG_WIRE_DOUBLE, error_estimate),
    STRING(ST, error_joint),
    SCALAR(ST, LAG_WIRE_DOUBLE, error_budget),
    SCALAR(ST, LAG_WIRE_INT64, error_warnings),
};

typedef lag_wire_scene SC;
static const lag_wire_field scene_fields[] = {
    SCALAR(SC, LAG_WIRE_INT64, utime),
    STRING(SC, model),
    STRING(SC, prefix),
    COUNT(SC, num_params, LAG_WIRE_MAX_PARAMS, false),          /* 3 */
    ARRAY(SC, LAG_WIRE_STRING, param_name, 3),
    ARRAY(SC, LAG_WIRE_DOUBLE, param_value, 3),
    COUNT(SC, num_joints, LAG_WIRE_MAX_JOINTS, true),           /* 6 */
    ARRAY(SC, LAG_WIRE_STRING, joint_name, 6),
    ARRAY(SC, LAG_WIRE_BOOLEAN, actuated, 6),
    ARRAY(SC, LAG_WIRE_DOUBLE, initial_q, 6),
    ARRAY(SC, LAG_WIRE_DOUBLE, initial_qd, 6),
    SCALAR(SC, LAG_WIRE_DOUBLE, dt),
    SCALAR(SC, LAG_WIRE_DOUBLE, control_period),
    STRING(SC, integrator),
    STRING(SC, mode),
    SCALAR(SC, LAG_WIRE_DOUBLE, rate),
    SCALAR(SC, LAG_WIRE_DOUBLE, command_timeout),
    STRING(SC, effects),
    ARRAY(SC, LAG_WIRE_BOOLEAN, limit_on, 6),
    ARRAY(SC, LAG_WIRE_DOUBLE, limit_lower, 6),
    ARRAY(SC, LAG_WIRE_DOUBLE, limit_upper, 6),
    SCALAR(SC, LAG_WIRE_INT64, generation),                     /* 0.2.0 */
};

/* The C storage of each kind must be what the decoder writes. */
_Static_assert(sizeof(bool) == 1, "booleans are stored in one byte");
_Static_assert(MEMBER_SIZE(JS, num_joints) == 2 && MEMBER_SIZE(SC, num_params) == 2,
               "counts are int16_t");

/* An earlier version of a type: the lagsim version whose types it is, how many of
 * today's fields it had (a type changes only by fields appended at its end), and the
 * fingerprint lcm-gen gave it (a unit test recomputes it from those fields). Appended,
 * never removed: a log of any earlier version stays readable. */
typedef struct old_version {
    const char *lagsim;
    int nfields;
    int64_t fingerprint;
} old_version;

#define OLD_MAX 4
typedef struct type_info {
    const char *name;
    const lag_wire_field *fields;
    int nfields;
    size_t struct_size;
    int64_t (*fingerprint)(void);
    old_version old[OLD_MAX]; /* oldest first; lagsim NULL: no more */
} type_info;

/* lagsim 0.1.0's types: today's without the fields 0.2.0 appended (`generation`; and
 * reference_t's `rddot`) */
#define V010(f, fp) {"0.1.0", (int)(sizeof f / sizeof f[0]) - 1, (int64_t)fp}
#define V010N(n, fp) {"0.1.0", n, (int64_t)fp}

#define TYPE(n, f, T, h, ...) {n, f, (int)(sizeof f / sizeof f[0]), sizeof(T), h, {__VA_ARGS__}}
static const type_info types[LAG_WIRE_TYPE_COUNT] = {
    [LAG_WIRE_JOINT_STATE] = TYPE("joint_state_t", joint_state_fields, JS,
                                  __lagsim_joint_state_t_get_hash,
                                  V010(joint_state_fields, 0x30d0440423c83571)),
    [LAG_WIRE_JOINT_COMMAND] = TYPE("joint_command_t", joint_command_fields, JC,
                                    __lagsim_joint_command_t_get_hash,
                                    V010(joint_command_fields, 0xf7fc3ec714ff2ae8)),
    [LAG_WIRE_CONTROL] = TYPE("control_t", control_fields, CT, __lagsim_control_t_get_hash),
    [LAG_WIRE_EVENT] = TYPE("event_t", event_fields, EV, __lagsim_event_t_get_hash),
    [LAG_WIRE_STATUS] = TYPE("status_t", status_fields, ST, __lagsim_status_t_get_hash),
    [LAG_WIRE_SCENE] = TYPE("scene_t", scene_fields, SC, __lagsim_scene_t_get_hash,
                            V010(scene_fields, 0x1ab54f27e2c0e262)),
    [LAG_WIRE_REFERENCE] = TYPE("reference_t", reference_fields, RF,
                                __lagsim_reference_t_get_hash,
                                V010N(7, 0x450a576ca1059690)),
};
_Static_assert(sizeof types / sizeof types[0] == LAG_WIRE_TYPE_COUNT,
               "one table per message type");

static const type_info *type_get(lag_wire_type t)
{
    return (unsigned)t < LAG_WIRE_TYPE_COUNT ? &types[t] : NULL;
}

/* ---------------------------------------------------------------- bounded reader */
typedef struct rd {
    const uint8_t *p;
    size_t len, pos;
} rd;

/* Reads an n-byte big-endian unsigned integer; false if fewer bytes are left. */
static bool rd_u(rd *r, int n, uint64_t *v)
{
    if (r->len - r->pos < (size_t)n) return false;
    uint64_t x = 0;
    for (int i = 0; i < n; i++) x = (x << 8) | r->p[r->pos + (size_t)i];
    r->pos += (size_t)n;
    *v = x;
    return true;
}

/* An LCM string into dst[cap]. ESHORT/ESTRING stop the decoding; ETOOLONG means the
 * string is well formed and was skipped, its first cap-1 bytes kept in dst. */
static int rd_string(rd *r, char *dst, size_t cap)
{
    uint64_t u;
    if (!rd_u(r, 4, &u)) return LAG_WIRE_ESHORT;
    int32_t n = (int32_t)(uint32_t)u;
    if (n < 1) return LAG_WIRE_ESTRING;
    if ((size_t)n > r->len - r->pos) return LAG_WIRE_ESHORT;
    const uint8_t *b = r->p + r->pos;
    if (b[n - 1] != 0 || memchr(b, 0, (size_t)n - 1) != NULL) return LAG_WIRE_ESTRING;
    r->pos += (size_t)n;
    if ((size_t)n > cap) {
        memcpy(dst, b, cap - 1);
        dst[cap - 1] = '\0';
        return LAG_WIRE_ETOOLONG;
    }
    memcpy(dst, b, (size_t)n);
    return LAG_WIRE_OK;
}

/* One element of kind k into dst. */
static int rd_elem(rd *r, lag_wire_kind k, uint8_t *dst, size_t size)
{
    uint64_t u;
    switch (k) {
    case LAG_WIRE_INT8: {
        if (!rd_u(r, 1, &u)) return LAG_WIRE_ESHORT;
        int8_t v = (int8_t)(uint8_t)u;
        memcpy(dst, &v, sizeof v);
        return LAG_WIRE_OK;
    }
    case LAG_WIRE_INT16: {
        if (!rd_u(r, 2, &u)) return LAG_WIRE_ESHORT;
        int16_t v = (int16_t)(uint16_t)u;
        memcpy(dst, &v, sizeof v);
        return LAG_WIRE_OK;
    }
    case LAG_WIRE_INT64: {
        if (!rd_u(r, 8, &u)) return LAG_WIRE_ESHORT;
        int64_t v = (int64_t)u;
        memcpy(dst, &v, sizeof v);
        return LAG_WIRE_OK;
    }
    case LAG_WIRE_DOUBLE: {
        if (!rd_u(r, 8, &u)) return LAG_WIRE_ESHORT;
        double v;
        memcpy(&v, &u, sizeof v);
        memcpy(dst, &v, sizeof v);
        return LAG_WIRE_OK;
    }
    case LAG_WIRE_BOOLEAN: {
        if (!rd_u(r, 1, &u)) return LAG_WIRE_ESHORT;
        if (u > 1) return LAG_WIRE_EVALUE;
        bool v = u != 0;
        memcpy(dst, &v, sizeof v);
        return LAG_WIRE_OK;
    }
    case LAG_WIRE_STRING:
        return rd_string(r, (char *)dst, size);
    }
    return LAG_WIRE_EARG;
}

/* The value of an int16 count field already stored in the struct. */
static int count_value(const uint8_t *msg, const lag_wire_field *f)
{
    int16_t n;
    memcpy(&n, msg + f->offset, sizeof n);
    return n;
}

/* The number of fields of the version of ti whose fingerprint is `hash` (today's, or,
 * when `old` allows, an earlier one's, named in *written_by), or -1. */
static int version_fields(const type_info *ti, int64_t hash, bool old, const char **written_by)
{
    if (written_by) *written_by = NULL;
    if (hash == ti->fingerprint()) return ti->nfields;
    for (int k = 0; old && k < OLD_MAX && ti->old[k].lagsim; k++)
        if (hash == ti->old[k].fingerprint) {
            if (written_by) *written_by = ti->old[k].lagsim;
            return ti->old[k].nfields;
        }
    return -1;
}

static int decode(lag_wire_type t, const void *data, size_t len, int max_joints, void *out,
                  bool old, const char **written_by)
{
    const type_info *ti = type_get(t);
    if (written_by) *written_by = NULL;
    if (!ti || !out) return LAG_WIRE_EARG;
    uint8_t *msg = out;
    memset(msg, 0, ti->struct_size);
    if (!data) return LAG_WIRE_EARG;
    if (max_joints < 0) max_joints = 0;
    if (max_joints > LAG_WIRE_MAX_JOINTS) max_joints = LAG_WIRE_MAX_JOINTS;
    rd r = {data, len, 0};
    uint64_t hash;
    if (!rd_u(&r, 8, &hash)) return LAG_WIRE_EFINGERPRINT;
    int nfields = version_fields(ti, (int64_t)hash, old, written_by);
    if (nfields < 0) return LAG_WIRE_EFINGERPRINT;
    bool too_long = false;
    for (int k = 0; k < nfields; k++) {
        const lag_wire_field *f = &ti->fields[k];
        uint8_t *dst = msg + f->offset;
        int n = 1;
        if (f->count_field >= 0) n = count_value(msg, &ti->fields[f->count_field]);
        for (int i = 0; i < n; i++) {
            int rc = rd_elem(&r, f->kind, dst + (size_t)i * f->size, f->size);
            if (rc == LAG_WIRE_ETOOLONG) too_long = true;
            else if (rc != LAG_WIRE_OK) return rc;
        }
        if (f->capacity > 0 && f->count_field < 0) {
            /* a count: checked as soon as it is read, before any array uses it */
            int c = count_value(msg, f);
            if (c < 0 || c > f->capacity || (f->joint_count && c > max_joints))
                return LAG_WIRE_ECOUNT;
        }
    }
    if (r.pos != r.len) return LAG_WIRE_ETRAILING;
    return too_long ? LAG_WIRE_ETOOLONG : LAG_WIRE_OK;
}

int lag_wire_decode(lag_wire_type t, const void *data, size_t len, int max_joints, void *out)
{
    return decode(t, data, len, max_joints, out, false, NULL);
}

int lag_wire_decode_any(lag_wire_type t, const void *data, size_t len, int max_joints,
                        void *out, const char **written_by)
{
    return decode(t, data, len, max_joints, out, true, written_by);
}

/* ---------------------------------------------------------------- bounded writer */
typedef struct wr {
    uint8_t *p;
    size_t cap, pos;
} wr;

static bool wr_u(wr *w, int n, uint64_t v)
{
    if (w->cap - w->pos < (size_t)n) return false;
    for (int i = n - 1; i >= 0; i--) {
        w->p[w->pos + (size_t)i] = (uint8_t)(v & 0xff);
        v >>= 8;
    }
    w->pos += (size_t)n;
    return true;
}

static int wr_elem(wr *w, lag_wire_kind k, const uint8_t *src, size_t size)
{
    switch (k) {
    case LAG_WIRE_INT8: {
        int8_t v;
        memcpy(&v, src, sizeof v);
        return wr_u(w, 1, (uint8_t)v) ? LAG_WIRE_OK : LAG_WIRE_ESPACE;
    }
    case LAG_WIRE_INT16: {
        int16_t v;
        memcpy(&v, src, sizeof v);
        return wr_u(w, 2, (uint16_t)v) ? LAG_WIRE_OK : LAG_WIRE_ESPACE;
    }
    case LAG_WIRE_INT64: {
        int64_t v;
        memcpy(&v, src, sizeof v);
        return wr_u(w, 8, (uint64_t)v) ? LAG_WIRE_OK : LAG_WIRE_ESPACE;
    }
    case LAG_WIRE_DOUBLE: {
        double v;
        memcpy(&v, src, sizeof v);
        if (!isfinite(v)) return LAG_WIRE_ENONFINITE;
        uint64_t u;
        memcpy(&u, &v, sizeof u);
        return wr_u(w, 8, u) ? LAG_WIRE_OK : LAG_WIRE_ESPACE;
    }
    case LAG_WIRE_BOOLEAN: {
        uint8_t b;
        memcpy(&b, src, 1);
        return wr_u(w, 1, b != 0) ? LAG_WIRE_OK : LAG_WIRE_ESPACE;
    }
    case LAG_WIRE_STRING: {
        const char *s = (const char *)src;
        const char *nul = memchr(s, 0, size);
        if (!nul) return LAG_WIRE_ESTRING; /* no NUL inside its field */
        size_t n = (size_t)(nul - s) + 1;
        if (!wr_u(w, 4, (uint32_t)n) || w->cap - w->pos < n) return LAG_WIRE_ESPACE;
        memcpy(w->p + w->pos, s, n);
        w->pos += n;
        return LAG_WIRE_OK;
    }
    }
    return LAG_WIRE_EARG;
}

int lag_wire_encode(lag_wire_type t, const void *m, void *buf, size_t cap)
{
    const type_info *ti = type_get(t);
    if (!ti || !m || !buf) return LAG_WIRE_EARG;
    if (cap > (size_t)INT32_MAX) cap = (size_t)INT32_MAX; /* the result fits an int */
    const uint8_t *msg = m;
    wr w = {buf, cap, 0};
    if (!wr_u(&w, 8, (uint64_t)ti->fingerprint())) return LAG_WIRE_ESPACE;
    for (int k = 0; k < ti->nfields; k++) {
        const lag_wire_field *f = &ti->fields[k];
        const uint8_t *src = msg + f->offset;
        int n = 1;
        if (f->count_field >= 0) n = count_value(msg, &ti->fields[f->count_field]);
        if (f->capacity > 0 && f->count_field < 0) {
            int c = count_value(msg, f);
            if (c < 0 || c > f->capacity) return LAG_WIRE_ECOUNT;
        }
        for (int i = 0; i < n; i++) {
            int rc = wr_elem(&w, f->kind, src + (size_t)i * f->size, f->size);
            if (rc != LAG_WIRE_OK) return rc;
        }
    }
    return (int)w.pos;
}

/* ---------------------------------------------------------------- per-type wrappers */
int lag_wire_decode_joint_state(const void *data, size_t len, int max_joints,
                                lag_wire_joint_state *out)
{
    return lag_wire_decode(LAG_WIRE_JOINT_STATE, data, len, max_joints, out);
}
int lag_wire_decode_joint_command(const void *data, size_t len, int max_joints,
                                  lag_wire_joint_command *out)
{
    return lag_wire_decode(LAG_WIRE_JOINT_COMMAND, data, len, max_joints, out);
}
int lag_wire_decode_control(const void *data, size_t len, int max_joints, lag_wire_control *out)
{
    return lag_wire_decode(LAG_WIRE_CONTROL, data, len, max_joints, out);
}
int lag_wire_decode_event(const void *data, size_t len, lag_wire_event *out)
{
    return lag_wire_decode(LAG_WIRE_EVENT, data, len, LAG_WIRE_MAX_JOINTS, out);
}
int lag_wire_decode_status(const void *data, size_t len, lag_wire_status *out)
{
    return lag_wire_decode(LAG_WIRE_STATUS, data, len, LAG_WIRE_MAX_JOINTS, out);
}
int lag_wire_decode_scene(const void *data, size_t len, int max_joints, lag_wire_scene *out)
{
    return lag_wire_decode(LAG_WIRE_SCENE, data, len, max_joints, out);
}
int lag_wire_decode_reference(const void *data, size_t len, int max_joints,
                              lag_wire_reference *out)
{
    return lag_wire_decode(LAG_WIRE_REFERENCE, data, len, max_joints, out);
}

int lag_wire_encode_joint_state(const lag_wire_joint_state *m, void *buf, size_t cap)
{
    return lag_wire_encode(LAG_WIRE_JOINT_STATE, m, buf, cap);
}
int lag_wire_encode_joint_command(const lag_wire_joint_command *m, void *buf, size_t cap)
{
    return lag_wire_encode(LAG_WIRE_JOINT_COMMAND, m, buf, cap);
}
int lag_wire_encode_control(const lag_wire_control *m, void *buf, size_t cap)
{
    return lag_wire_encode(LAG_WIRE_CONTROL, m, buf, cap);
}
int lag_wire_encode_event(const lag_wire_event *m, void *buf, size_t cap)
{
    return lag_wire_encode(LAG_WIRE_EVENT, m, buf, cap);
}
int lag_wire_encode_status(const lag_wire_status *m, void *buf, size_t cap)
{
    return lag_wire_encode(LAG_WIRE_STATUS, m, buf, cap);
}
int lag_wire_encode_scene(const lag_wire_scene *m, void *buf, size_t cap)
{
    return lag_wire_encode(LAG_WIRE_SCENE, m, buf, cap);
}
int lag_wire_encode_reference(const lag_wire_reference *m, void *buf, size_t cap)
{
    return lag_wire_encode(LAG_WIRE_REFERENCE, m, buf, cap);
}

/* ---------------------------------------------------------------- introspection */
int lag_wire_identify(const void *data, size_t len)
{
    rd r = {data, len, 0};
    uint64_t hash;
    if (!data || !rd_u(&r, 8, &hash)) return -1;
    for (int t = 0; t < LAG_WIRE_TYPE_COUNT; t++)
        if ((int64_t)hash == types[t].fingerprint()) return t;
    return -1;
}

int lag_wire_identify_any(const void *data, size_t len, const char **written_by)
{
    rd r = {data, len, 0};
    uint64_t hash;
    if (written_by) *written_by = NULL;
    if (!data || !rd_u(&r, 8, &hash)) return -1;
    for (int t = 0; t < LAG_WIRE_TYPE_COUNT; t++)
        if (version_fields(&types[t], (int64_t)hash, true, written_by) >= 0) return t;
    return -1;
}

const char *lag_wire_version(void) { return LAGSIM_VERSION; }

int lag_wire_old_versions(lag_wire_type t)
{
    const type_info *ti = type_get(t);
    int n = 0;
    while (ti && n < OLD_MAX && ti->old[n].lagsim) n++;
    return n;
}

const char *lag_wire_old_version(lag_wire_type t, int k, int *nfields, int64_t *fingerprint)
{
    if (k < 0 || k >= lag_wire_old_versions(t)) return NULL;
    const old_version *v = &types[t].old[k];
    if (nfields) *nfields = v->nfields;
    if (fingerprint) *fingerprint = v->fingerprint;
    return v->lagsim;
}

int64_t lag_wire_fingerprint(lag_wire_type t)
{
    const type_info *ti = type_get(t);
    return ti ? ti->fingerprint() : 0;
}

static const char *const kind_names[] = {
    [LAG_WIRE_INT8] = "int8_t",   [LAG_WIRE_INT16] = "int16_t",   [LAG_WIRE_INT64] = "int64_t",
    [LAG_WIRE_DOUBLE] = "double", [LAG_WIRE_BOOLEAN] = "boolean", [LAG_WIRE_STRING] = "string",
};
_Static_assert(sizeof kind_names / sizeof kind_names[0] == LAG_WIRE_STRING + 1,
               "a name for every kind");

const char *lag_wire_kind_name(lag_wire_kind k)
{
    return (unsigned)k <= LAG_WIRE_STRING ? kind_names[k] : "?";
}

/* LCM's type fingerprint (lcm-gen, lcmgen.c: lcm_struct_hash), in unsigned arithmetic:
 * v = ((v << 8) ^ (v >> 55)) + c with an arithmetic shift of the signed 64-bit v. */
static uint64_t hash_update(uint64_t v, int c)
{
    uint64_t sar55 = (v >> 55) | ((v >> 63) ? ~(~(uint64_t)0 >> 55) : 0);
    return ((v << 8) ^ sar55) + (uint64_t)(int64_t)(signed char)c;
}

static uint64_t hash_string(uint64_t v, const char *s)
{
    v = hash_update(v, (int)strlen(s));
    for (; *s; s++) v = hash_update(v, *s);
    return v;
}

int64_t lag_wire_table_fingerprint(lag_wire_type t)
{
    const type_info *ti = type_get(t);
    return ti ? lag_wire_table_fingerprint_n(t, ti->nfields) : 0;
}

int64_t lag_wire_table_fingerprint_n(lag_wire_type t, int nfields)
{
    const type_info *ti = type_get(t);
    if (!ti || nfields < 0 || nfields > ti->nfields) return 0;
    uint64_t v = 0x12345678;
    for (int k = 0; k < nfields; k++) {
        const lag_wire_field *f = &ti->fields[k];
        v = hash_string(v, f->name);
        v = hash_string(v, lag_wire_kind_name(f->kind)); /* every field is a primitive */
        if (f->count_field < 0) {
            v = hash_update(v, 0); /* no dimension */
        } else {
            v = hash_update(v, 1);
            v = hash_update(v, 1); /* a variable dimension (LCM_VAR) ... */
            v = hash_string(v, ti->fields[f->count_field].name); /* ... named by its count */
        }
    }
    /* what the generated __<type>_get_hash returns for a type without nested types */
    return (int64_t)((v << 1) + ((v >> 63) & 1));
}

const char *lag_wire_request_name(int request)
{
    static const char *const names[] = {
        [LAGSIM_CONTROL_T_PAUSE] = "PAUSE", [LAGSIM_CONTROL_T_RESUME] = "RESUME",
        [LAGSIM_CONTROL_T_STEP] = "STEP", [LAGSIM_CONTROL_T_RESET] = "RESET",
        [LAGSIM_CONTROL_T_RESET_TO] = "RESET_TO", [LAGSIM_CONTROL_T_STATUS] = "STATUS",
        [LAGSIM_CONTROL_T_DESCRIBE] = "DESCRIBE", [LAGSIM_CONTROL_T_SET] = "SET"};
    const int n = (int)(sizeof names / sizeof names[0]);
    return request >= 0 && request < n ? names[request] : NULL;
}

const char *lag_wire_type_name(lag_wire_type t)
{
    const type_info *ti = type_get(t);
    return ti ? ti->name : NULL;
}

size_t lag_wire_struct_size(lag_wire_type t)
{
    const type_info *ti = type_get(t);
    return ti ? ti->struct_size : 0;
}

const lag_wire_field *lag_wire_fields(lag_wire_type t, int *n)
{
    const type_info *ti = type_get(t);
    if (n) *n = ti ? ti->nfields : 0;
    return ti ? ti->fields : NULL;
}

static size_t kind_max_size(lag_wire_kind k, size_t size)
{
    switch (k) {
    case LAG_WIRE_INT8:
    case LAG_WIRE_BOOLEAN: return 1;
    case LAG_WIRE_INT16: return 2;
    case LAG_WIRE_INT64:
    case LAG_WIRE_DOUBLE: return 8;
    case LAG_WIRE_STRING: return 4 + size;
    }
    return 0;
}

size_t lag_wire_max_size(lag_wire_type t)
{
    const type_info *ti = type_get(t);
    if (!ti) return 0;
    size_t n = 8;
    for (int k = 0; k < ti->nfields; k++) {
        const lag_wire_field *f = &ti->fields[k];
        size_t count = f->count_field >= 0 ? (size_t)ti->fields[f->count_field].capacity : 1;
        n += count * kind_max_size(f->kind, f->size);
    }
    return n;
}

bool lag_wire_all_finite(lag_wire_type t, const void *m)
{
    const type_info *ti = type_get(t);
    if (!ti || !m) return false;
    const uint8_t *msg = m;
    for (int k = 0; k < ti->nfields; k++) {
        const lag_wire_field *f = &ti->fields[k];
        if (f->kind != LAG_WIRE_DOUBLE) continue;
        int n = 1;
        if (f->count_field >= 0) {
            n = count_value(msg, &ti->fields[f->count_field]);
            if (n < 0) n = 0;
            if (n > f->capacity) n = f->capacity;
        }
        for (int i = 0; i < n; i++) {
            double v;
            memcpy(&v, msg + f->offset + (size_t)i * f->size, sizeof v);
            if (!isfinite(v)) return false;
        }
    }
    return true;
}

const char *lag_wire_result_string(int r)
{
    switch (r) {
    case LAG_WIRE_OK: return "ok";
    case LAG_WIRE_EFINGERPRINT: return "not this message type (fingerprint)";
    case LAG_WIRE_ESHORT: return "payload ends inside the message";
    case LAG_WIRE_ECOUNT: return "array count out of range";
    case LAG_WIRE_ESTRING: return "malformed string (length < 1, no final NUL, or a NUL inside)";
    case LAG_WIRE_ETOOLONG: return "string longer than its field";
    case LAG_WIRE_EVALUE: return "boolean other than 0 or 1";
    case LAG_WIRE_ETRAILING: return "bytes after the end of the message";
    case LAG_WIRE_ENONFINITE: return "NaN or infinity";
    case LAG_WIRE_ESPACE: return "buffer too small";
    case LAG_WIRE_EARG: return "bad argument";
    }
    return "unknown result";
}
