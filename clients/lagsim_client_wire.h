/*
 * In-tree only (not installed, not part of the ABI): the wire module's messages behind the
 * client library's opaque scene and status, for the tools that print or check every field
 * of them (lagsimctl, the client's tests). Programs outside the tree use the accessors of
 * lagsim_client.h, which stay when the messages grow.
 */
#ifndef LAGSIM_CLIENT_WIRE_H
#define LAGSIM_CLIENT_WIRE_H

#include "lagsim_client.h"
#include "lagsim_wire.h"

#ifdef __cplusplus
extern "C" {
#endif

const lag_wire_scene *lag_wire_of_scene(const lag_client_scene *sc);
const lag_wire_status *lag_wire_of_status(const lag_client_status *st);
/* A state and an event of the client's as the wire module's messages (every field). */
void lag_wire_of_state(const lag_client_state *st, lag_wire_joint_state *out);
void lag_wire_of_event(const lag_client_event *ev, lag_wire_event *out);

#ifdef __cplusplus
}
#endif
#endif
