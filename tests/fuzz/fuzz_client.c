/*
 * Fuzz target: the C client library's handling of whatever arrives on a controller's
 * channels (the decoders of states, status, events, scenes and references behind the LCM
 * handlers).
 *
 * The first byte chooses the channel (<prefix>_STATE, _STATUS, _EVENT, _SCENE, _REFERENCE,
 * modulo 5); the rest
 * is the payload, fed to one client handle through lag_client_feed, the path of the bus.
 * Nothing may crash or leak; a message is kept or dropped (counted), never both; what
 * the handle returns afterwards is whole: counts within the structs, strings terminated,
 * every number finite.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "lagsim_client.h"
#include "lagsim_client_wire.h"

static lag_client *g_client;

static void fail(const char *what)
{
    fprintf(stderr, "fuzz_client: %s\n", what);
    abort();
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc, (void)argv;
    char err[256];
    g_client = lag_client_create("memq://", "FZ", err, sizeof err);
    if (!g_client) {
        fprintf(stderr, "fuzz_client: %s\n", err);
        exit(1);
    }
    return 0;
}

static void check_terminated(const char *s, size_t cap)
{
    if (!memchr(s, 0, cap)) fail("string without its NUL");
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    if (size < 1) return 0;
    static const char *const channels[] = {"FZ_STATE", "FZ_STATUS", "FZ_EVENT", "FZ_SCENE",
                                           "FZ_REFERENCE"};
    lag_client_counters before, after;
    lag_client_get_counters(g_client, &before, sizeof before);
    if (lag_client_feed(g_client, channels[data[0] % 5], data + 1, size - 1) != LAG_CLIENT_OK)
        fail("feed refused one of the handle's channels");
    lag_client_get_counters(g_client, &after, sizeof after);
    int64_t kept = (after.states - before.states) + (after.statuses - before.statuses) +
                   (after.events - before.events) + (after.scenes - before.scenes) +
                   (after.references - before.references);
    if (kept + (after.dropped - before.dropped) != 1) fail("a message neither kept nor dropped");

    lag_client_state st;
    if (lag_client_latest_state(g_client, &st, sizeof st)) {
        if (st.num_joints < 0 || st.num_joints > LAG_CLIENT_MAX_JOINTS) fail("state joints");
        for (int i = 0; i < st.num_joints; i++) {
            check_terminated(st.name[i], sizeof st.name[i]);
            if (!isfinite(st.position[i]) || !isfinite(st.velocity[i]) || !isfinite(st.effort[i]))
                fail("non-finite state");
        }
        if (!isfinite(st.sim_time)) fail("non-finite sim_time");
    }
    lag_client_reference rf;
    if (lag_client_latest_reference(g_client, &rf, sizeof rf)) {
        if (rf.num_joints < 0 || rf.num_joints > LAG_CLIENT_MAX_JOINTS) fail("reference joints");
        for (int i = 0; i < rf.num_joints; i++) {
            check_terminated(rf.name[i], sizeof rf.name[i]);
            if (!isfinite(rf.r[i]) || !isfinite(rf.rdot[i]) || !isfinite(rf.rddot[i]))
                fail("non-finite reference");
        }
        if (!isfinite(rf.sim_time)) fail("non-finite reference sim_time");
    }
    static lag_client_status *status;
    if (!status && !(status = lag_client_status_new())) fail("out of memory");
    if (lag_client_latest_status(g_client, status)) {
        const lag_wire_status *ss = lag_wire_of_status(status);
        check_terminated(ss->integrator, sizeof ss->integrator);
        check_terminated(ss->mode, sizeof ss->mode);
        check_terminated(ss->run_state, sizeof ss->run_state);
        check_terminated(ss->waiting_for, sizeof ss->waiting_for);
        check_terminated(ss->waiting_got, sizeof ss->waiting_got);
        if (!lag_wire_all_finite(LAG_WIRE_STATUS, ss)) fail("non-finite status");
        for (int i = 0; i < lag_client_status_fields(); i++) { /* through the accessors */
            const char *name = lag_client_status_field_name(i);
            if (lag_client_status_field_is_text(i) ? !lag_client_status_text(status, name)
                                                   : !isfinite(lag_client_status_number(status, name)))
                fail("a status field the accessors do not give");
        }
    }
    return 0;
}
