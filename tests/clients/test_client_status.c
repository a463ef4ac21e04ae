/*
 * Every field of status_t reaches C clients, one by one, with the field list read from
 * lcmtypes/status_t.lcm itself: a field added to the .lcm file and not carried through
 * to lag_client_status (its accessors lag_client_status_number and _text, by the field's
 * name) fails here, by name.
 *
 * For each field of the .lcm file, a status_t is built by this test's own encoder (from
 * the parsed field list; fingerprint: lcm-gen's) in which that field has a value of its
 * own and every other field is zero or empty, and is fed to a client handle on its
 * <prefix>_STATUS channel (the path of the bus). The field is then read from the client's
 * status through the accessors by its .lcm name and must hold the value; every other
 * field must still be zero or empty.
 *
 * usage: test_client_status status_fields LCMTYPES_DIR   (tests/common/lagsim_test.h)
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "lagsim/lagsim_status_t.h"
#include "lagsim_client.h"
#include "lagsim_test.h"
#include "lagsim_wire.h"
#include "lcm_fields.h"

static size_t put(uint8_t *b, size_t p, uint64_t v, int n)
{
    for (int i = n - 1; i >= 0; i--) b[p++] = (uint8_t)(v >> (8 * i));
    return p;
}

/* The value field k carries when it is the one set (0 otherwise). */
static int64_t int_value(int k) { return 1000003 * (int64_t)(k + 1); }
static double double_value(int k) { return 0.25 + (double)(k + 1); }

/* Encodes a status_t with field `set` holding its value, the others zero. Returns the
 * length, or 0 for a type this test does not know (it fails then). */
static size_t encode(const lcm_field *f, int n, int set, uint8_t *b)
{
    size_t p = put(b, 0, (uint64_t)__lagsim_status_t_get_hash(), 8);
    for (int k = 0; k < n; k++) {
        bool on = k == set;
        if (f[k].dim[0]) return 0; /* arrays: extend this test */
        if (!strcmp(f[k].type, "int64_t")) p = put(b, p, on ? (uint64_t)int_value(k) : 0, 8);
        else if (!strcmp(f[k].type, "int32_t")) p = put(b, p, on ? (uint64_t)int_value(k) : 0, 4);
        else if (!strcmp(f[k].type, "int16_t")) p = put(b, p, on ? (uint64_t)(k + 1) : 0, 2);
        else if (!strcmp(f[k].type, "int8_t")) p = put(b, p, on ? (uint64_t)(k + 1) : 0, 1);
        else if (!strcmp(f[k].type, "boolean")) p = put(b, p, on ? 1 : 0, 1);
        else if (!strcmp(f[k].type, "double")) {
            double d = on ? double_value(k) : 0.0;
            uint64_t u;
            memcpy(&u, &d, sizeof u);
            p = put(b, p, u, 8);
        } else if (!strcmp(f[k].type, "string")) {
            char s[32] = "";
            if (on) snprintf(s, sizeof s, "field%d", k);
            p = put(b, p, strlen(s) + 1, 4);
            memcpy(b + p, s, strlen(s) + 1);
            p += strlen(s) + 1;
        } else {
            return 0;
        }
    }
    return p;
}

/* Whether field k (named `name`, of type `type` in the .lcm file) of the client's status,
 * read through the accessors of lagsim_client.h by its name, holds its value (on) or
 * zero. */
static bool holds(const lag_client_status *s, const char *name, const char *type, int k,
                  bool on)
{
    if (!strcmp(type, "string")) {
        char want[32] = "";
        if (on) snprintf(want, sizeof want, "field%d", k);
        const char *t = lag_client_status_text(s, name);
        return t && strcmp(t, want) == 0 && isnan(lag_client_status_number(s, name));
    }
    double v = lag_client_status_number(s, name), want = 0;
    if (!strcmp(type, "int64_t") || !strcmp(type, "int32_t")) want = (double)int_value(k);
    else if (!strcmp(type, "int16_t") || !strcmp(type, "int8_t")) want = k + 1;
    else if (!strcmp(type, "boolean")) want = 1;
    else if (!strcmp(type, "double")) want = double_value(k);
    return v == (on ? want : 0.0) && lag_client_status_text(s, name) == NULL;
}

static void case_status_fields(int arg)
{
    (void)arg;
    char path[1024], err[256], ch[96];
    snprintf(path, sizeof path, "%s/status_t.lcm", lt_arg(0));
    lcm_field f[64];
    int n = parse_lcm(path, f, 64);
    ENSUREF(n > 20, "cannot read the fields of %s", path);
    int nw;
    const lag_wire_field *w = lag_wire_fields(LAG_WIRE_STATUS, &nw);
    /* the client's status member of each .lcm field, by name */
    int member[64];
    for (int k = 0; k < n; k++) {
        member[k] = -1;
        for (int j = 0; j < nw; j++)
            if (!strcmp(w[j].name, f[k].name)) member[k] = j;
        ENSUREF(member[k] >= 0, "status_t.%s (%s) does not reach C clients: lag_client_status "
                "has no such field", f[k].name, path);
        if (member[k] >= 0)
            ENSUREF(!strcmp(lag_wire_kind_name(w[member[k]].kind), f[k].type),
                    "status_t.%s is %s in the .lcm file, %s in lag_client_status", f[k].name,
                    f[k].type, lag_wire_kind_name(w[member[k]].kind));
    }

    lag_client *c = lag_client_create("memq://", "STATUSFIELDS", err, sizeof err);
    lag_client_status *s = lag_client_status_new();
    ENSUREF(c != NULL && s != NULL, "%s", err);
    if (!c || !s) return;
    snprintf(ch, sizeof ch, "STATUSFIELDS_STATUS");
    for (int k = 0; k < n; k++) {
        static uint8_t b[4096];
        size_t len = encode(f, n, k, b);
        ENSUREF(len > 0, "status_t.%s: type %s%s%s not handled by this test: extend encode()",
                f[k].name, f[k].type, f[k].dim[0] ? " array of " : "", f[k].dim);
        if (len == 0) continue;
        lag_client_counters before, after;
        lag_client_get_counters(c, &before, sizeof before);
        ENSURE(lag_client_feed(c, ch, b, len) == LAG_CLIENT_OK);
        lag_client_get_counters(c, &after, sizeof after);
        ENSUREF(after.statuses == before.statuses + 1,
                "status with status_t.%s set was dropped (the client does not decode the "
                ".lcm layout)", f[k].name);
        ENSURE(lag_client_latest_status(c, s));
        for (int j = 0; j < n; j++) {
            if (member[j] < 0) continue;
            bool on = j == k;
            ENSUREF(holds(s, f[j].name, f[j].type, j, on),
                    "status_t.%s %s when status_t.%s was set", f[j].name,
                    on ? "does not reach lag_client_status_number/_text" : "changed",
                    f[k].name);
        }
    }
    /* the accessors' list of fields is the .lcm file's, in its order */
    ENSUREF(lag_client_status_fields() == n, "%d fields listed, %d in the .lcm file",
            lag_client_status_fields(), n);
    for (int k = 0; k < n && k < lag_client_status_fields(); k++)
        ENSUREF(!strcmp(lag_client_status_field_name(k), f[k].name) &&
                    lag_client_status_field_is_text(k) == !strcmp(f[k].type, "string"),
                "field %d: %s listed, %s in the .lcm file", k, lag_client_status_field_name(k),
                f[k].name);
    lag_client_status_free(s);
    lag_client_destroy(c);
}

int main(int argc, char **argv)
{
    static const lt_case cases[] = {{"status_fields", case_status_fields, 0, 0}};
    const lt_program p = {.cases = cases, .n = 1, .args = "LCMTYPES_DIR", .min_args = 1,
                          .max_args = 1};
    return lt_run(argc, argv, &p);
}
