/*
 * What the daemon and the view (lagsim-view) do to LCM's receive sockets, and what they
 * say about the network.
 *
 * LCM's udpm provider binds its receive socket to INADDR_ANY:PORT and joins the group on
 * the interface the routing table gives for it (the default route's, usually): a peer on
 * that network sending with ttl >= 1 reaches it, whatever ttl this process sends with.
 * LCM 1.3.1 has no option against that (its udpm options are ttl and recv_buf_size), so
 * the program finds LCM's receive socket (the one of this process bound to the port) and
 * attaches a classic BPF socket filter to it:
 *   - from this host only (lcm.allow_lan false): a datagram is kept if the kernel looped
 *     it back from a local sender (pkttype PACKET_LOOPBACK) or it arrived on the loopback
 *     interface (a route 224.0.0.0/4 dev lo); what comes in from a network is dropped by
 *     the kernel before LCM reads it;
 *   - channels: only LCM short messages ("LC02") on the named channels (and, for
 *     lag_net_filter_suffixes, on any channel with one of the named suffixes) are kept,
 *     so a flood on another prefix's channels costs this process nothing (but on the
 *     suffixes it names).
 * A datagram already queued when the filter is attached went past it: lag_net_sync reads
 * until a marker sent after the attachment comes back, so that the caller can discard
 * everything that arrived before.
 */
#ifndef LAGSIMD_LAG_NET_H
#define LAGSIMD_LAG_NET_H

#include <stdbool.h>
#include <stddef.h>
#include <lcm/lcm.h>

#define LAG_NET_MAX_FILTER_CHANNELS 6 /* the view: its five and the marker */
#define LAG_NET_MARKER_CHANNEL "LCM_SELF_TEST" /* the channel LCM's own self-test uses */

/* Attaches the filter to every UDP socket of this process bound to `port`, but those
 * noted by lag_net_note_inherited (LCM's receive
 * socket of an lcm_t for that port, once it has a subscription): keep only LCM short
 * messages on one of the n channels (exact names), and with
 * host_only only those sent from this host. Returns the number of sockets filtered (0: none found), or -1 with a
 * message in err. */
int lag_net_filter(int port, bool host_only, const char *const *channels, int n, char *err,
                  size_t errlen);

/* lag_net_filter, keeping also every channel whose name ends in one of the ns suffixes
 * after a prefix of at least one byte ("_CONTROL": every plant's control requests), so
 * that a program hears what is asked of a prefix that is not its own (a misspelt one).
 * What a suffix lets in costs this process a wake-up a datagram: name only the channels
 * of requests, never a plant's stream of states or commands. */
int lag_net_filter_suffixes(int port, bool host_only, const char *const *channels, int n,
                            const char *const *suffixes, int ns, char *err, size_t errlen);

/* The filter of lag_net_filter_suffixes on one socket of the caller's own (fd), with the
 * `except` channels (exact names) dropped before anything is kept: a socket for every
 * prefix's requests but this plant's own. n may be 0 when ns is not. Returns 0, or -1
 * with a message in err. */
int lag_net_filter_fd(int fd, bool host_only, const char *const *channels, int n,
                      const char *const *suffixes, int ns, const char *const *except, int ne,
                      char *err, size_t errlen);

/* Notes the UDP sockets this process has now, before it creates its LCM instances:
 * lag_net_filter leaves them alone (a parent that forked without close-on-exec shares
 * them, and a filter would cut the parent's own traffic). The first call notes; the later
 * ones do nothing (by then the process has sockets of its own: a host's plants each call
 * it before making theirs). */
void lag_net_note_inherited(void);

/* Sends a marker on LAG_NET_MARKER_CHANNEL through lcm and handles lcm's messages until it
 * comes back (every message queued before it has then been handed to its handlers), at
 * most timeout_ms. The caller's handlers discard what they get meanwhile. The marker's
 * channel must pass the socket's filter. Returns 0, or -1 if it did not come back. */
int lag_net_sync(lcm_t *lcm, int timeout_ms);

/* The interface the kernel joins a multicast group on for a socket that does not name
 * one: the route to the group in the main table (/proc/net/route, longest prefix, lowest
 * metric). Writes its name into ifname ("?" if unknown). Returns 0, or -1 when no route
 * leads to the group. */
int lag_net_group_iface(const char *group, char *ifname, size_t len);

#endif
