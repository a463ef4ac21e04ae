/*
 * A pair of UDP ports of this host for a bus of one's own: the state port P (even) and the
 * command port P + 1 (lagsim_bus.h), that no other holder on this host has and no socket
 * of this host is bound to. lagsim-eval and lagsim-sweep take one for each bus they run
 * (docs/evaluation.md, "Ports").
 *
 * Held, not hoped: a pair is held by an exclusive flock(2) on its lock file,
 * LAG_PORT_LOCK_DIR/lagsim-udp-P.lock, for as long as the lease's descriptor is open (the
 * holder's lifetime: close-on-exec, so the programs it starts do not keep it; a child it
 * forks shares it). flock works on a descriptor opened read-only, so every user can lock
 * a file another user created: the directory is the host's directory of lock files
 * (/run/lock, Debian's FHS /var/lock: sticky and writable by all, a local tmpfs emptied at
 * boot), not $XDG_RUNTIME_DIR (one user's) nor a program's own (two users would not see
 * each other's locks). A lock file is never removed (removing a locked file lets a second
 * holder lock a new file of the same name); the files are empty, one per pair ever used.
 *
 * A program that takes no lease (a lagsimd run by hand, a test with a port of its own)
 * cannot be held off by a lock: a pair with a UDP socket bound to either port
 * (/proc/net/udp, /proc/net/udp6, this network namespace) is skipped, so a tool never
 * joins a bus in use when it takes the pair. A program that binds one afterwards shares
 * it; its channels are its own prefix's.
 *
 * A lock file that cannot be one (a symbolic link, a FIFO, a file another user made
 * unreadable) makes its pair unusable, never the search hang or fail as a whole.
 */
#ifndef LAGSIM_PORT_H
#define LAGSIM_PORT_H

#include <stdbool.h>
#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

#define LAG_PORT_FIRST 64000       /* the pairs of the tools: state ports 64000, 64002, ... */
#define LAG_PORT_LAST 65534        /* ... up to 65534 (commands on 65535): 768 pairs */
#define LAG_PORT_LOCK_DIR "/run/lock"

typedef struct lag_port_lease {
    int port; /* the state port (even); commands on port + 1; 0: none held */
    int fd;   /* the lock file's descriptor, flock-ed; -1: none */
} lag_port_lease;

/* Takes the first free pair of the range first..last (state ports, both even), the search
 * starting at pair number `start` (modulo the pairs of the range) and wrapping around, its
 * lock file in dir. Returns 0 and holds the pair in *l, or -1 with why in err (every pair
 * held or bound, or no lock file could be had in dir). OUT: l */
int lag_port_take_in(const char *dir, int first, int last, unsigned start, lag_port_lease *l,
                     char *err, size_t errlen);

/* lag_port_take_in with the host's lock directory (LAG_PORT_LOCK_DIR, else /var/lock, else
 * /tmp: the first that exists) and the range LAG_PORT_FIRST..LAG_PORT_LAST, starting at a
 * place drawn from the process id (holders seldom meet). OUT: l */
int lag_port_take(lag_port_lease *l, char *err, size_t errlen);

/* n consecutive pairs (l[0].port, l[0].port + 2, ...) of the tools' range, each held as
 * lag_port_take holds one: a host of n plants on its --port-base. Returns 0, or -1 with why
 * in err (none held then). OUT: l[0..n) */
int lag_port_take_block(int n, lag_port_lease *l, char *err, size_t errlen);

/* Lets the pair go (its lock file stays). The lease is then none. */
void lag_port_release(lag_port_lease *l);

/* Whether a UDP socket of this host (this network namespace) is bound to port: 1, 0, or
 * -1 when /proc/net/udp cannot be read. */
int lag_port_bound(int port);

#ifdef __cplusplus
}
#endif
#endif
