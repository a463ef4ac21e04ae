/*
 * The loop of lagsimd's real-time server (host.c): one loop for the plants of one process.
 *
 *   lagsimd --config S                 one plant (lagsimd_realtime): its scene's failure is
 *                                      the daemon's (exit 2), it ends when the plant ends
 *   lagsimd --plants DIR [--config S]  a host (lagsimd_host): every DIR/NAME.yaml a plant of
 *   lagsimd --config S1 --config S2    its own, each with its prefix, port pair, mode,
 *                                      lockstep, --log and start rule; a scene that fails
 *                                      is said and skipped, the others run
 *
 * One timer paces them all: the loop waits (rt_io.h) until the earliest thing any plant
 * has due, then processes the plants that are due or heard something, in one pass, so
 * that plants due at the same deadline are stepped and published together. Signals are
 * read once: SIGINT, SIGTERM, SIGQUIT stop every plant; SIGUSR1/SIGUSR2 ask each for a
 * status; SIGHUP stops a daemon of one plant (as always) and makes a host read DIR again.
 *
 * A host reads DIR again on SIGHUP and when inotify says a file of it changed (after a
 * quiet 0.2 s, as editors write in steps): a new NAME.yaml starts a plant, a changed one
 * stops its plant and starts it again from the new bytes on the same ports (a new file
 * that fails to load is said, and the old plant runs on), a removed one stops its plant.
 * No other plant is touched.
 */
#ifndef LAGSIMD_HOST_H
#define LAGSIMD_HOST_H

#include <stdbool.h>
#include "daemon.h"

/* What the command line gives a host. */
typedef struct host_conf {
    const char *dir;            /* --plants DIR, NULL: none */
    const char *const *configs; /* --config FILE, each a plant */
    int nconfigs;
    const char *const *sets;    /* --set, applied to every plant (after its file) */
    int nsets;
    int port_base;              /* --port-base P: plants whose scene gives no lcm.url get the
                                 * pairs P, P + 2, ... (the first free); 0: none */
    lagsimd_opts opts;          /* for every plant: -q, --duration, --log (each plant's in
                                 * a directory of its own name), --log-buffer, ... */
} host_conf;

/* A host of plants until SIGINT/SIGTERM/SIGQUIT; with --duration, or without DIR, until
 * every plant has stopped. Returns LAG_OK; LAGSIMD_EXIT_USAGE when no plant could start
 * (and none can come: no DIR); LAGSIMD_EXIT_RUNTIME when a plant's --log lost records or
 * the wait failed. */
lag_result lagsimd_host(const host_conf *c);

#endif
