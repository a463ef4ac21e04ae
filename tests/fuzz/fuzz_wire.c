/*
 * Fuzz target: the wire module's decoders and encoders on arbitrary bytes.
 *
 * The first byte chooses the caller's bound on num_joints (-1 .. 9); the rest is decoded
 * as each of lagsim's six message types. Whatever the bytes, decoding must not crash,
 * read outside the payload or allocate; a decoded message must have its counts within
 * the bound and its strings NUL-terminated inside their fields; and a message decodes
 * only if encoding the result gives back exactly the payload (when every number in it is
 * finite; otherwise the encoder must refuse it).
 */
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim_wire.h"

static void fail(const char *what, int t)
{
    fprintf(stderr, "fuzz_wire: %s (%s)\n", what, lag_wire_type_name((lag_wire_type)t));
    abort();
}

/* Counts within bounds, strings terminated inside their fields. */
static void check_struct(int t, const uint8_t *msg, int max_joints)
{
    int n;
    const lag_wire_field *f = lag_wire_fields((lag_wire_type)t, &n);
    for (int k = 0; k < n; k++) {
        if (f[k].capacity > 0 && f[k].count_field < 0) {
            int16_t c;
            memcpy(&c, msg + f[k].offset, sizeof c);
            if (c < 0 || c > f[k].capacity || (f[k].joint_count && c > max_joints))
                fail("count out of its bound", t);
        }
        if (f[k].kind == LAG_WIRE_STRING) {
            int elems = f[k].count_field >= 0 ? f[k].capacity : 1;
            for (int i = 0; i < elems; i++)
                if (!memchr(msg + f[k].offset + (size_t)i * f[k].size, 0, f[k].size))
                    fail("string without its NUL", t);
        }
    }
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1) return 0;
    int max_joints = (int)(data[0] % 11) - 1;
    const uint8_t *p = data + 1;
    size_t n = size - 1;
    static uint8_t msg[8192], out[LAG_WIRE_BUF_SIZE];
    int bound = max_joints < 0 ? 0 : max_joints > LAG_WIRE_MAX_JOINTS ? LAG_WIRE_MAX_JOINTS
                                                                         : max_joints;
    int identified = lag_wire_identify(p, n);
    for (int t = 0; t < LAG_WIRE_TYPE_COUNT; t++) {
        int rc = lag_wire_decode((lag_wire_type)t, p, n, max_joints, msg);
        if (rc > 0) fail("positive decode result", t);
        if (rc == LAG_WIRE_OK || rc == LAG_WIRE_ETOOLONG) check_struct(t, msg, bound);
        if (rc != LAG_WIRE_OK) continue;
        if (identified != t) fail("decoded but identified as another type", t);
        int ne = lag_wire_encode((lag_wire_type)t, msg, out, sizeof out);
        if (lag_wire_all_finite((lag_wire_type)t, msg)) {
            if (ne != (int)n || memcmp(out, p, n) != 0) fail("decode then encode differs", t);
        } else if (ne != LAG_WIRE_ENONFINITE) {
            fail("a non-finite number was encoded", t);
        }
    }
    return 0;
}
