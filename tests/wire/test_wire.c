/*
 * Unit test of the wire module (server/wire/lagsim_wire.c).
 *
 *   tables     each table's fingerprint, computed with LCM's algorithm, equals lcm-gen's;
 *              each table lists exactly the fields of its .lcm file, in order, with their
 *              types and dimensions (the .lcm files are parsed here, independently);
 *              counts, capacities and offsets are consistent; every full message fits
 *              LAG_WIRE_BUF_SIZE.
 *   agreement  for every type, our encoder writes exactly the bytes of lcm-gen's encoder
 *              for the same message, and our decoder reads them back to the same struct.
 *   hostile    every class of bad payload gives its result, never a crash: a fingerprint
 *              of another type, every proper prefix of a valid message, negative and
 *              oversized counts (the count is reported), string lengths of -1, 0, past the
 *              end, 0x7fffffff, a missing or an inner NUL, a string longer than its field
 *              (the rest is still checked), a boolean of 2, a trailing byte.
 *   encoder    NaN and infinities refused, every buffer shorter than the message refused
 *              without a byte written past it, counts above the capacity and strings
 *              without their NUL refused.
 *
 * usage: test_wire messages LCMTYPES_DIR   (tests/common/lagsim_test.h)
 */
#include <ctype.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim/lagsim_control_t.h"
#include "lagsim/lagsim_event_t.h"
#include "lagsim/lagsim_joint_command_t.h"
#include "lagsim/lagsim_joint_state_t.h"
#include "lagsim/lagsim_reference_t.h"
#include "lagsim/lagsim_scene_t.h"
#include "lagsim/lagsim_status_t.h"
#include "lagsim_test.h"
#include "lagsim_wire.h"
#include "lcm_fields.h"

static void check_tables(const char *lcmdir)
{
    for (int t = 0; t < LAG_WIRE_TYPE_COUNT; t++) {
        const char *tn = lag_wire_type_name((lag_wire_type)t);
        ENSUREF(lag_wire_table_fingerprint((lag_wire_type)t) == lag_wire_fingerprint((lag_wire_type)t),
                "%s: the table's fingerprint %016llx is not lcm-gen's %016llx", tn,
                (unsigned long long)lag_wire_table_fingerprint((lag_wire_type)t),
                (unsigned long long)lag_wire_fingerprint((lag_wire_type)t));
        int n;
        const lag_wire_field *f = lag_wire_fields((lag_wire_type)t, &n);
        char path[1024];
        snprintf(path, sizeof path, "%s/%s.lcm", lcmdir, tn);
        lcm_field lf[64];
        int m = parse_lcm(path, lf, 64);
        ENSUREF(m > 0, "cannot parse %s", path);
        ENSUREF(m == n, "%s: %d fields in the .lcm file, %d in the table", tn, m, n);
        for (int k = 0; k < n && k < m; k++) {
            ENSUREF(strcmp(f[k].name, lf[k].name) == 0, "%s field %d: table %s, .lcm %s", tn, k,
                    f[k].name, lf[k].name);
            ENSUREF(strcmp(lag_wire_kind_name(f[k].kind), lf[k].type) == 0,
                    "%s.%s: table %s, .lcm %s", tn, f[k].name, lag_wire_kind_name(f[k].kind),
                    lf[k].type);
            const char *dim = f[k].count_field >= 0 ? f[f[k].count_field].name : "";
            ENSUREF(strcmp(dim, lf[k].dim) == 0, "%s.%s: dimension %s, .lcm %s", tn, f[k].name,
                    dim, lf[k].dim);
        }
        /* consistency of the table itself */
        size_t ssize = lag_wire_struct_size((lag_wire_type)t);
        for (int k = 0; k < n; k++) {
            int c = f[k].count_field;
            size_t elems = c >= 0 ? (size_t)f[k].capacity : 1;
            ENSUREF(f[k].offset + elems * f[k].size <= ssize, "%s.%s outside its struct", tn,
                    f[k].name);
            if (c >= 0) {
                ENSUREF(c < k && f[c].kind == LAG_WIRE_INT16 && f[c].count_field < 0,
                        "%s.%s: its count must be an earlier int16 scalar", tn, f[k].name);
                ENSUREF(f[k].capacity >= f[c].capacity && f[c].capacity > 0,
                        "%s.%s holds %d, its count allows %d", tn, f[k].name, f[k].capacity,
                        f[c].capacity);
            }
        }
        ENSUREF(lag_wire_max_size((lag_wire_type)t) <= LAG_WIRE_BUF_SIZE,
                "%s: up to %zu bytes", tn, lag_wire_max_size((lag_wire_type)t));
    }
    ENSURE(lag_wire_type_name(LAG_WIRE_TYPE_COUNT) == NULL);
    ENSURE(lag_wire_decode(LAG_WIRE_TYPE_COUNT, "", 0, 8, NULL) == LAG_WIRE_EARG);
}

/* ---------------------------------------------------------------- agreement */
static uint8_t ours[LAG_WIRE_BUF_SIZE], theirs[LAG_WIRE_BUF_SIZE];

/* Our encoding of m equals lcm-gen's (theirs[0..nt)), and decodes back to it. */
static void agree(lag_wire_type t, const void *m, int nt)
{
    const char *tn = lag_wire_type_name(t);
    int no = lag_wire_encode(t, m, ours, sizeof ours);
    ENSUREF(no == nt && nt > 0, "%s: %d bytes, lcm-gen %d", tn, no, nt);
    ENSUREF(no == nt && memcmp(ours, theirs, (size_t)nt) == 0, "%s: bytes differ", tn);
    static uint8_t back[8192], again[LAG_WIRE_BUF_SIZE];
    /* an exact-size copy, so that a read past the end is seen by ASan */
    uint8_t *exact = malloc((size_t)nt);
    memcpy(exact, theirs, (size_t)nt);
    int rc = lag_wire_decode(t, exact, (size_t)nt, LAG_WIRE_MAX_JOINTS, back);
    ENSUREF(rc == LAG_WIRE_OK, "%s: decode %s", tn, lag_wire_result_string(rc));
    int na = lag_wire_encode(t, back, again, sizeof again);
    ENSUREF(na == nt && memcmp(again, theirs, (size_t)nt) == 0, "%s: decode+encode differs", tn);
    /* every proper prefix fails cleanly */
    for (int k = 0; k < nt; k++) {
        uint8_t *pre = malloc(k ? (size_t)k : 1);
        memcpy(pre, theirs, (size_t)k);
        rc = lag_wire_decode(t, pre, (size_t)k, LAG_WIRE_MAX_JOINTS, back);
        ENSUREF(rc == (k < 8 ? LAG_WIRE_EFINGERPRINT : LAG_WIRE_ESHORT), "%s: prefix %d: %s",
                tn, k, lag_wire_result_string(rc));
        free(pre);
    }
    /* one byte more */
    uint8_t *longer = malloc((size_t)nt + 1);
    memcpy(longer, theirs, (size_t)nt);
    longer[nt] = 0;
    ENSURE(lag_wire_decode(t, longer, (size_t)nt + 1, LAG_WIRE_MAX_JOINTS, back) == LAG_WIRE_ETRAILING);
    free(longer);
    /* another type's decoder refuses it */
    for (int u = 0; u < LAG_WIRE_TYPE_COUNT; u++)
        if (u != (int)t)
            ENSURE(lag_wire_decode((lag_wire_type)u, exact, (size_t)nt, 8, back) == LAG_WIRE_EFINGERPRINT);
    ENSURE(lag_wire_identify(exact, (size_t)nt) == (int)t);
    /* every buffer too short is refused, nothing written past it */
    for (int cap = 0; cap < nt; cap++) {
        memset(again, 0xCC, sizeof again);
        ENSUREF(lag_wire_encode(t, m, again, (size_t)cap) == LAG_WIRE_ESPACE, "%s cap %d", tn, cap);
        bool clean = true;
        for (size_t i = (size_t)cap; i < sizeof again; i++) clean &= again[i] == 0xCC;
        ENSUREF(clean, "%s: cap %d: written past the buffer", tn, cap);
    }
    free(exact);
}

static void check_agreement(void)
{
    {
        char *names[3] = {"theta0", "theta1", "th\xc3\xa9ta2"};
        double p[3] = {0.5, -1e-300, 3}, v[3] = {-0.0, 2.5, 1e300}, e[3] = {1, 0, -7};
        lagsim_joint_state_t g = {123456789, 1.25, 1250, 3, names, p, v, e};
        int nt = lagsim_joint_state_t_encode(theirs, 0, sizeof theirs, &g);
        lag_wire_joint_state w;
        memset(&w, 0, sizeof w);
        w.utime = 123456789;
        w.sim_time = 1.25;
        w.step = 1250;
        w.num_joints = 3;
        for (int i = 0; i < 3; i++) {
            strcpy(w.name[i], names[i]);
            w.position[i] = p[i];
            w.velocity[i] = v[i];
            w.effort[i] = e[i];
        }
        agree(LAG_WIRE_JOINT_STATE, &w, nt);
        /* no joints at all */
        g.num_joints = 0;
        w.num_joints = 0;
        nt = lagsim_joint_state_t_encode(theirs, 0, sizeof theirs, &g);
        agree(LAG_WIRE_JOINT_STATE, &w, nt);
    }
    {
        /* a reference of two of three joints, and of none */
        char *names[2] = {"theta0", "theta2"};
        double r[2] = {0.2, -1e-300}, rd[2] = {-0.0, 6.283185307179586};
        double rdd[2] = {-39.47841760435743, 1e300};
        lagsim_reference_t g = {12, 1.5, 1500, 2, names, r, rd, 5, rdd};
        int nt = lagsim_reference_t_encode(theirs, 0, sizeof theirs, &g);
        lag_wire_reference w;
        memset(&w, 0, sizeof w);
        w.utime = 12;
        w.sim_time = 1.5;
        w.step = 1500;
        w.num_joints = 2;
        w.generation = 5;
        for (int i = 0; i < 2; i++) {
            strcpy(w.name[i], names[i]);
            w.r[i] = r[i];
            w.rdot[i] = rd[i];
            w.rddot[i] = rdd[i];
        }
        agree(LAG_WIRE_REFERENCE, &w, nt);
        g.num_joints = 0;
        w.num_joints = 0;
        nt = lagsim_reference_t_encode(theirs, 0, sizeof theirs, &g);
        agree(LAG_WIRE_REFERENCE, &w, nt);
    }
    {
        char *names[2] = {"q1", ""};
        double e[2] = {1.5, -2.25};
        lagsim_joint_command_t g = {-5, 0.01, 2, names, e};
        int nt = lagsim_joint_command_t_encode(theirs, 0, sizeof theirs, &g);
        lag_wire_joint_command w;
        memset(&w, 0, sizeof w);
        w.utime = -5;
        w.sim_time = 0.01;
        w.num_joints = 2;
        strcpy(w.name[0], "q1");
        w.effort[0] = 1.5;
        w.effort[1] = -2.25;
        agree(LAG_WIRE_JOINT_COMMAND, &w, nt);
    }
    {
        double q[2] = {0.1, 0.2}, qd[2] = {-0.3, 0.4};
        lagsim_control_t g = {7, LAGSIM_CONTROL_T_RESET_TO, INT64_MAX, 2, q, qd, "", ""};
        int nt = lagsim_control_t_encode(theirs, 0, sizeof theirs, &g);
        lag_wire_control w;
        memset(&w, 0, sizeof w);
        w.utime = 7;
        w.request = LAGSIM_CONTROL_T_RESET_TO;
        w.count = INT64_MAX;
        w.num_joints = 2;
        memcpy(w.q, q, sizeof q);
        memcpy(w.qd, qd, sizeof qd);
        agree(LAG_WIRE_CONTROL, &w, nt);
    }
    {
        lagsim_control_t g = {8, LAGSIM_CONTROL_T_SET, 0, 0, NULL, NULL, "effects.friction.q2",
                              "{static: 0.3, kinetic: 0.2}"};
        int nt = lagsim_control_t_encode(theirs, 0, sizeof theirs, &g);
        lag_wire_control w;
        memset(&w, 0, sizeof w);
        w.utime = 8;
        w.request = LAGSIM_CONTROL_T_SET;
        snprintf(w.key, sizeof w.key, "effects.friction.q2");
        snprintf(w.value, sizeof w.value, "{static: 0.3, kinetic: 0.2}");
        agree(LAG_WIRE_CONTROL, &w, nt);
    }
    {
        char detail[LAG_WIRE_TEXT_LEN];
        memset(detail, 'd', sizeof detail - 1);
        detail[sizeof detail - 1] = '\0'; /* exactly fills its field */
        lagsim_event_t g = {1, 2.5, 2500, "impact", "theta1", -0.5, detail};
        int nt = lagsim_event_t_encode(theirs, 0, sizeof theirs, &g);
        lag_wire_event w;
        memset(&w, 0, sizeof w);
        w.utime = 1;
        w.sim_time = 2.5;
        w.step = 2500;
        strcpy(w.kind, "impact");
        strcpy(w.joint, "theta1");
        w.value = -0.5;
        memcpy(w.detail, detail, sizeof detail);
        agree(LAG_WIRE_EVENT, &w, nt);
    }
    {
        lagsim_status_t g;
        memset(&g, 0, sizeof g);
        lag_wire_status w;
        memset(&w, 0, sizeof w);
        /* every field a different value */
        g.utime = w.utime = 1;
        g.sim_time = w.sim_time = 2.5;
        g.step = w.step = 3;
        g.wall_time = w.wall_time = 4.5;
        g.rtf = w.rtf = 5.5;
        g.overruns = w.overruns = 6;
        g.step_time_max_us = w.step_time_max_us = 7.5;
        g.step_time_mean_us = w.step_time_mean_us = 8.5;
        g.energy = w.energy = 9.5;
        g.integrator = "dopri5";
        strcpy(w.integrator, "dopri5");
        g.mode = "lockstep";
        strcpy(w.mode, "lockstep");
        g.run_state = "paused";
        strcpy(w.run_state, "paused");
        g.commands_accepted = w.commands_accepted = 13;
        g.rejected_unknown_joint = w.rejected_unknown_joint = 14;
        g.rejected_unactuated = w.rejected_unactuated = 15;
        g.rejected_nonfinite = w.rejected_nonfinite = 16;
        g.rejected_bad_length = w.rejected_bad_length = 17;
        g.rejected_undecodable = w.rejected_undecodable = 18;
        g.controls_rejected = w.controls_rejected = 19;
        g.watchdog_tripped = 1;
        w.watchdog_tripped = true;
        g.watchdog_trips = w.watchdog_trips = 21;
        g.lockstep_timeouts = w.lockstep_timeouts = 22;
        g.numeric_faults = w.numeric_faults = 23;
        g.rejected_stale = w.rejected_stale = 24;
        g.overrun_bursts = w.overrun_bursts = 25;
        g.states_published = w.states_published = 26;
        g.rejected_effort_limit = w.rejected_effort_limit = 27;
        g.lockstep_retries = w.lockstep_retries = 28;
        g.commands_ignored = w.commands_ignored = 29;
        g.contact = "flight";
        strcpy(w.contact, "flight");
        g.plant_conflicts = w.plant_conflicts = 30;
        g.waiting_for = "the first command on X_COMMAND at udpm://239.255.76.67:7668?ttl=0";
        strcpy(w.waiting_for, g.waiting_for);
        g.waiting_s = w.waiting_s = 30.5;
        g.waiting_got = "2 commands rejected (unknown joint 2; the last: unknown joint: 'cart')";
        strcpy(w.waiting_got, g.waiting_got);
        g.commands_wrong_port = w.commands_wrong_port = 31;
        g.error_estimate = w.error_estimate = 31.5;
        g.error_joint = "theta1";
        strcpy(w.error_joint, "theta1");
        g.error_budget = w.error_budget = 33.5;
        g.error_warnings = w.error_warnings = 34;
        int nt = lagsim_status_t_encode(theirs, 0, sizeof theirs, &g);
        agree(LAG_WIRE_STATUS, &w, nt);
    }
    {
        char *pn[3] = {"m0", "l1", "g"}, *jn[3] = {"theta0", "theta1", "theta2"};
        double pv[3] = {1.5, 0.5, 9.81}, q0[3] = {0, 0.1, -0.05}, qd0[3] = {0, 0, 1};
        int8_t act[3] = {1, 0, 0}, lon[3] = {1, 0, 0};
        double llo[3] = {-0.5, 0, 0}, lhi[3] = {0.5, 0, 0};
        lagsim_scene_t g = {.utime = 99, .model = "dipc", .prefix = "DIPC", .num_params = 3,
                            .param_name = pn, .param_value = pv, .num_joints = 3,
                            .joint_name = jn, .actuated = act, .initial_q = q0,
                            .initial_qd = qd0, .dt = 0.001, .control_period = 0.01,
                            .integrator = "rk4", .mode = "realtime", .rate = 1.0,
                            .command_timeout = 0.5, .effects = "limits,noise",
                            .limit_on = lon, .limit_lower = llo, .limit_upper = lhi};
        int nt = lagsim_scene_t_encode(theirs, 0, sizeof theirs, &g);
        lag_wire_scene w;
        memset(&w, 0, sizeof w);
        w.utime = 99;
        strcpy(w.model, "dipc");
        strcpy(w.prefix, "DIPC");
        w.num_params = 3;
        w.num_joints = 3;
        for (int i = 0; i < 3; i++) {
            strcpy(w.param_name[i], pn[i]);
            w.param_value[i] = pv[i];
            strcpy(w.joint_name[i], jn[i]);
            w.actuated[i] = act[i] != 0;
            w.initial_q[i] = q0[i];
            w.initial_qd[i] = qd0[i];
            w.limit_on[i] = lon[i] != 0;
            w.limit_lower[i] = llo[i];
            w.limit_upper[i] = lhi[i];
        }
        strcpy(w.effects, "limits,noise");
        w.dt = 0.001;
        w.control_period = 0.01;
        strcpy(w.integrator, "rk4");
        strcpy(w.mode, "realtime");
        w.rate = 1.0;
        w.command_timeout = 0.5;
        agree(LAG_WIRE_SCENE, &w, nt);
    }
}

/* ---------------------------------------------------------------- hostile payloads */
static size_t put_be(uint8_t *b, size_t p, uint64_t v, int n)
{
    for (int i = n - 1; i >= 0; i--) b[p + (size_t)(n - 1 - i)] = (uint8_t)(v >> (8 * i));
    return p + (size_t)n;
}

/* A joint_state_t header up to num_joints (the first string's length comes next). */
static size_t state_head(uint8_t *b, int16_t n)
{
    size_t p = put_be(b, 0, (uint64_t)lag_wire_fingerprint(LAG_WIRE_JOINT_STATE), 8);
    p = put_be(b, p, 1, 8);      /* utime */
    p = put_be(b, p, 0, 8);      /* sim_time 0.0 */
    p = put_be(b, p, 0, 8);      /* step */
    return put_be(b, p, (uint16_t)n, 2);
}

static int decode_exact(lag_wire_type t, const uint8_t *b, size_t n, int max_joints, void *out)
{
    uint8_t *c = malloc(n ? n : 1);
    memcpy(c, b, n);
    int rc = lag_wire_decode(t, c, n, max_joints, out);
    free(c);
    return rc;
}

static void check_hostile(void)
{
    static uint8_t b[1 << 16];
    lag_wire_joint_state st;
    size_t p;

    /* a forged state of 145 bytes: num_joints 1, name length -1 */
    p = state_head(b, 1);
    p = put_be(b, p, 0xffffffffu, 4);
    memset(b + p, 'A', 145 - p);
    ENSURE(decode_exact(LAG_WIRE_JOINT_STATE, b, 145, 8, &st) == LAG_WIRE_ESTRING);
    /* string lengths 0, 0x7fffffff, one past the end */
    int32_t lens[] = {0, INT32_MAX, INT32_MIN, 100};
    int expect[] = {LAG_WIRE_ESTRING, LAG_WIRE_ESHORT, LAG_WIRE_ESTRING, LAG_WIRE_ESHORT};
    for (int k = 0; k < 4; k++) {
        p = state_head(b, 1);
        p = put_be(b, p, (uint32_t)lens[k], 4);
        memset(b + p, 'x', 99);
        b[p + 98] = 0;
        ENSUREF(decode_exact(LAG_WIRE_JOINT_STATE, b, p + 99, 8, &st) == expect[k],
                "string length %d", lens[k]);
    }
    /* a name exactly filling its field without a NUL; an inner NUL */
    p = state_head(b, 1);
    p = put_be(b, p, LAG_WIRE_NAME_LEN, 4);
    memset(b + p, 'n', LAG_WIRE_NAME_LEN);
    p += LAG_WIRE_NAME_LEN;
    memset(b + p, 0, 24); /* three doubles */
    p += 24;
    ENSURE(decode_exact(LAG_WIRE_JOINT_STATE, b, p, 8, &st) == LAG_WIRE_ESTRING);
    p = state_head(b, 1);
    p = put_be(b, p, 4, 4);
    memcpy(b + p, "x\0y", 4);
    p += 4;
    memset(b + p, 0, 24); /* three doubles */
    p += 24;
    ENSURE(decode_exact(LAG_WIRE_JOINT_STATE, b, p, 8, &st) == LAG_WIRE_ESTRING);
    /* counts: negative, above capacity, above the caller's bound; the count is reported */
    int16_t counts[] = {-1, INT16_MIN, 9, INT16_MAX};
    for (int k = 0; k < 4; k++) {
        p = state_head(b, counts[k]);
        ENSURE(decode_exact(LAG_WIRE_JOINT_STATE, b, p, 8, &st) == LAG_WIRE_ECOUNT);
        ENSURE(st.num_joints == counts[k]);
    }
    /* a valid state of 3 joints is refused by a caller expecting at most 2 */
    char *names[3] = {"a", "b", "c"};
    double z[3] = {0, 0, 0};
    lagsim_joint_state_t g = {0, 0, 0, 3, names, z, z, z};
    int nt = lagsim_joint_state_t_encode(b, 0, sizeof b, &g);
    ENSURE(decode_exact(LAG_WIRE_JOINT_STATE, b, (size_t)nt, 2, &st) == LAG_WIRE_ECOUNT);
    ENSURE(decode_exact(LAG_WIRE_JOINT_STATE, b, (size_t)nt, 3, &st) == LAG_WIRE_OK);
    ENSURE(decode_exact(LAG_WIRE_JOINT_STATE, b, (size_t)nt, 1000, &st) == LAG_WIRE_OK);
    ENSURE(decode_exact(LAG_WIRE_JOINT_STATE, b, (size_t)nt, -5, &st) == LAG_WIRE_ECOUNT);
    /* a name longer than its field: ETOOLONG when the rest is good, its first bytes kept */
    char longname[200];
    memset(longname, 'L', sizeof longname - 1);
    longname[sizeof longname - 1] = '\0';
    names[1] = longname;
    nt = lagsim_joint_state_t_encode(b, 0, sizeof b, &g);
    ENSURE(decode_exact(LAG_WIRE_JOINT_STATE, b, (size_t)nt, 8, &st) == LAG_WIRE_ETOOLONG);
    ENSURE(strlen(st.name[1]) == LAG_WIRE_NAME_LEN - 1 && strcmp(st.name[2], "c") == 0);
    ENSURE(decode_exact(LAG_WIRE_JOINT_STATE, b, (size_t)nt - 1, 8, &st) == LAG_WIRE_ESHORT);
    /* a boolean of 2 */
    char *jn[1] = {"x"};
    int8_t act[1] = {2};
    double one[1] = {1};
    int8_t nolim[1] = {0};
    lagsim_scene_t s = {.model = "m", .prefix = "P", .num_joints = 1, .joint_name = jn,
                        .actuated = act, .initial_q = one, .initial_qd = one,
                        .integrator = "rk4", .mode = "fast", .effects = "",
                        .limit_on = nolim, .limit_lower = one, .limit_upper = one};
    nt = lagsim_scene_t_encode(b, 0, sizeof b, &s);
    lag_wire_scene sc;
    ENSURE(decode_exact(LAG_WIRE_SCENE, b, (size_t)nt, 8, &sc) == LAG_WIRE_EVALUE);
    act[0] = 1;
    nt = lagsim_scene_t_encode(b, 0, sizeof b, &s);
    ENSURE(decode_exact(LAG_WIRE_SCENE, b, (size_t)nt, 8, &sc) == LAG_WIRE_OK && sc.actuated[0]);
    /* NaN and infinities are decoded as sent (the caller decides) */
    double nan1[1] = {NAN};
    s.initial_q = nan1;
    nt = lagsim_scene_t_encode(b, 0, sizeof b, &s);
    ENSURE(decode_exact(LAG_WIRE_SCENE, b, (size_t)nt, 8, &sc) == LAG_WIRE_OK);
    ENSURE(isnan(sc.initial_q[0]) && !lag_wire_all_finite(LAG_WIRE_SCENE, &sc));
    /* random bytes after a good fingerprint never crash (and almost never decode) */
    uint64_t x = 88172645463325252ull;
    for (int it = 0; it < 20000; it++) {
        lag_wire_type t = (lag_wire_type)(it % LAG_WIRE_TYPE_COUNT);
        size_t n = 8 + (size_t)(it % 300);
        put_be(b, 0, (uint64_t)lag_wire_fingerprint(t), 8);
        for (size_t i = 8; i < n; i++) {
            x ^= x << 13, x ^= x >> 7, x ^= x << 17;
            b[i] = (uint8_t)((x & 0x300) ? (x & 3) : x); /* mostly small bytes: short counts */
        }
        static uint8_t out[8192];
        int rc = decode_exact(t, b, n, 8, out);
        if (rc == LAG_WIRE_OK) {
            /* decodes only if it re-encodes to the same bytes */
            int ne = lag_wire_encode(t, out, ours, sizeof ours);
            if (lag_wire_all_finite(t, out))
                ENSURE(ne == (int)n && memcmp(ours, b, n) == 0);
        }
    }
}

/* ---------------------------------------------------------------- encoder */
static void check_encoder(void)
{
    lag_wire_joint_command c;
    memset(&c, 0, sizeof c);
    c.num_joints = 1;
    strcpy(c.name[0], "theta0");
    double bad[] = {NAN, INFINITY, -INFINITY};
    for (int k = 0; k < 3; k++) {
        c.effort[0] = bad[k];
        ENSURE(lag_wire_encode_joint_command(&c, ours, sizeof ours) == LAG_WIRE_ENONFINITE);
    }
    c.effort[0] = 1.0;
    c.sim_time = NAN;
    ENSURE(lag_wire_encode_joint_command(&c, ours, sizeof ours) == LAG_WIRE_ENONFINITE);
    c.sim_time = 0;
    c.num_joints = LAG_WIRE_MAX_JOINTS + 1;
    ENSURE(lag_wire_encode_joint_command(&c, ours, sizeof ours) == LAG_WIRE_ECOUNT);
    c.num_joints = -1;
    ENSURE(lag_wire_encode_joint_command(&c, ours, sizeof ours) == LAG_WIRE_ECOUNT);
    c.num_joints = 1;
    memset(c.name[0], 'x', LAG_WIRE_NAME_LEN); /* no NUL inside the field */
    ENSURE(lag_wire_encode_joint_command(&c, ours, sizeof ours) == LAG_WIRE_ESTRING);
    ENSURE(lag_wire_encode(LAG_WIRE_TYPE_COUNT, &c, ours, sizeof ours) == LAG_WIRE_EARG);
    ENSURE(lag_wire_encode_joint_command(NULL, ours, sizeof ours) == LAG_WIRE_EARG);

    /* a message full to capacity encodes to exactly lag_wire_max_size */
    lag_wire_scene s;
    memset(&s, 'a', sizeof s);
    s.num_params = LAG_WIRE_MAX_PARAMS;
    s.num_joints = LAG_WIRE_MAX_JOINTS;
    char *strs[] = {s.model, s.prefix, s.integrator, s.mode, s.effects};
    for (int k = 0; k < 5; k++) strs[k][LAG_WIRE_NAME_LEN - 1] = '\0';
    for (int i = 0; i < LAG_WIRE_MAX_PARAMS; i++) {
        s.param_name[i][LAG_WIRE_NAME_LEN - 1] = '\0';
        s.param_value[i] = i;
    }
    for (int i = 0; i < LAG_WIRE_MAX_JOINTS; i++) {
        s.joint_name[i][LAG_WIRE_NAME_LEN - 1] = '\0';
        s.actuated[i] = true;
        s.limit_on[i] = true;
        s.initial_q[i] = s.initial_qd[i] = 0;
        s.limit_lower[i] = s.limit_upper[i] = 0;
    }
    s.utime = 0;
    s.dt = s.control_period = s.rate = s.command_timeout = 1;
    int n = lag_wire_encode_scene(&s, ours, sizeof ours);
    ENSUREF(n == (int)lag_wire_max_size(LAG_WIRE_SCENE), "%d vs %zu", n,
            lag_wire_max_size(LAG_WIRE_SCENE));
    lag_wire_scene back;
    ENSURE(lag_wire_decode_scene(ours, (size_t)n, LAG_WIRE_MAX_JOINTS, &back) == LAG_WIRE_OK);
    ENSURE(strcmp(back.joint_name[7], s.joint_name[7]) == 0);
    for (int r = 0; r >= LAG_WIRE_EARG; r--)
        ENSURE(strcmp(lag_wire_result_string(r), "unknown result") != 0);
}

/* Each type's earlier versions (docs/wire.md, "How message types evolve"): the
 * fingerprint kept for lagsim 0.1.0 is what LCM's algorithm gives today's table without
 * its appended fields (and what 0.1.0's lcm-gen gave: the constants are 0.1.0's), only
 * appended fields changed, and a message of that version decodes in logs (the new fields
 * 0) but not on the bus (lag_wire_decode: today's version only). */
static void check_old_versions(void)
{
    int changed = 0;
    for (int t = 0; t < LAG_WIRE_TYPE_COUNT; t++) {
        const lag_wire_type ty = (lag_wire_type)t;
        const char *tn = lag_wire_type_name(ty);
        int n;
        lag_wire_fields(ty, &n);
        for (int k = 0; k < lag_wire_old_versions(ty); k++) {
            int nf;
            int64_t fp;
            const char *v = lag_wire_old_version(ty, k, &nf, &fp);
            changed++;
            ENSUREF(v && nf > 0 && nf < n, "%s: version %d keeps %d of %d fields", tn, k, nf, n);
            ENSUREF(lag_wire_table_fingerprint_n(ty, nf) == fp,
                    "%s %s: the fingerprint kept %016llx is not that of its %d fields %016llx",
                    tn, v, (unsigned long long)fp, nf,
                    (unsigned long long)lag_wire_table_fingerprint_n(ty, nf));
            /* a message of that version: today's bytes without the appended fields, under
             * the old fingerprint: every count 1, so that an appended array holds one
             * element; the appended fields are int64 scalars (a generation) or double
             * arrays counted by an earlier field (reference_t's rddot), each 77 */
            static _Alignas(max_align_t) uint8_t m[8192], back[8192];
            uint8_t buf[LAG_WIRE_BUF_SIZE];
            memset(m, 0, sizeof m);
            const lag_wire_field *f = lag_wire_fields(ty, &n);
            for (int j = 0; j < n; j++)
                if (f[j].capacity > 0 && f[j].count_field < 0) { /* a count */
                    int16_t one = 1;
                    memcpy(m + f[j].offset, &one, sizeof one);
                }
            int appended = 0; /* bytes */
            for (int j = nf; j < n; j++) {
                bool scalar = f[j].kind == LAG_WIRE_INT64 && f[j].count_field < 0;
                bool array = f[j].kind == LAG_WIRE_DOUBLE && f[j].count_field >= 0 &&
                             f[j].count_field < nf;
                ENSUREF(scalar || array,
                        "%s.%s: an appended field other than an int64 scalar or a double array "
                        "counted by an earlier field", tn, f[j].name);
                if (scalar) {
                    int64_t g = 77;
                    memcpy(m + f[j].offset, &g, sizeof g);
                } else {
                    double x = 77;
                    memcpy(m + f[j].offset, &x, sizeof x);
                }
                appended += 8;
            }
            int len = lag_wire_encode(ty, m, buf, sizeof buf);
            ENSUREF(len > 8 + appended, "%s: encoded %d bytes", tn, len);
            len -= appended;
            for (int b = 0; b < 8; b++) buf[b] = (uint8_t)((uint64_t)fp >> (56 - 8 * b));
            const char *by = "?";
            ENSURE(lag_wire_decode(ty, buf, (size_t)len, LAG_WIRE_MAX_JOINTS, back) ==
                   LAG_WIRE_EFINGERPRINT);
            ENSURE(lag_wire_identify(buf, (size_t)len) == -1);
            ENSUREF(lag_wire_decode_any(ty, buf, (size_t)len, LAG_WIRE_MAX_JOINTS, back, &by) ==
                        LAG_WIRE_OK && by && !strcmp(by, v),
                    "%s %s: not read as that version", tn, v);
            ENSURE(lag_wire_identify_any(buf, (size_t)len, &by) == t && !strcmp(by, v));
            for (int j = nf; j < n; j++) {
                int64_t g;
                memcpy(&g, back + f[j].offset, sizeof g); /* an int64 or a double's bits */
                ENSUREF(g == 0, "%s.%s of a %s message: %lld, not 0", tn, f[j].name, v,
                        (long long)g);
            }
            /* today's bytes read as today's, by both */
            len = lag_wire_encode(ty, m, buf, sizeof buf);
            ENSURE(lag_wire_decode_any(ty, buf, (size_t)len, LAG_WIRE_MAX_JOINTS, back, &by) ==
                   LAG_WIRE_OK && by == NULL);
        }
    }
    /* 0.2.0 appended the generation to the state, the reference, the scene, the command
     * (and r'' to the reference) */
    ENSUREF(changed == 4, "%d types with an earlier version", changed);
    ENSURE(strcmp(lag_wire_version(), "0.1.0") > 0); /* today's types are newer */
}

static void case_messages(int arg)
{
    (void)arg;
    check_tables(lt_arg(0));
    check_old_versions();
    check_agreement();
    check_hostile();
    check_encoder();
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {{"messages", case_messages, 0, 0}};
    const lt_program p = {.cases = cases, .n = 1, .args = "LCMTYPES_DIR", .min_args = 1,
                          .max_args = 1};
    return lt_run(argc, argv, &p);
}
