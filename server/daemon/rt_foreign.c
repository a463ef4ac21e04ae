/*
 * Requests heard for other prefixes, or on the wrong port: see rt_foreign.h.
 */
#include "rt_foreign.h"

#include <stdio.h>
#include <string.h>

#include "lagsim_bus.h"
#include "lagsim_wire.h"
#include "lagsim/lagsim_control_t.h"

/* The prefix of a channel that ends in `suffix` (len bytes before it), or 0. */
static size_t prefix_len(const char *channel, const char *suffix)
{
    size_t n = strlen(channel), m = strlen(suffix);
    return n > m && n - m < RT_FOREIGN_NAME && !strcmp(channel + n - m, suffix) ? n - m : 0;
}

/* The entry of the prefix (len bytes of pre), or NULL. */
static rt_foreign_prefix *find(rt_foreign *f, const char *pre, size_t len)
{
    for (int i = 0; i < RT_FOREIGN_MAX; i++) {
        rt_foreign_prefix *e = &f->p[i];
        if (e->prefix[0] && strlen(e->prefix) == len && !memcmp(e->prefix, pre, len)) return e;
    }
    return NULL;
}

/* Whether a should go before b: a free slot first, then a prefix with a plant (never
 * reported), then the least recently heard. */
static bool goes_first(const rt_foreign_prefix *a, const rt_foreign_prefix *b)
{
    if (!a->prefix[0] || !b->prefix[0]) return !a->prefix[0] && b->prefix[0];
    if (a->has_plant != b->has_plant) return a->has_plant;
    return a->heard < b->heard;
}

/* The entry of the prefix, made when it is not there (in the slot that goes first). */
static rt_foreign_prefix *entry(rt_foreign *f, const char *pre, size_t len)
{
    rt_foreign_prefix *e = find(f, pre, len);
    if (e) return e;
    e = &f->p[0];
    for (int i = 1; i < RT_FOREIGN_MAX; i++)
        if (goes_first(&f->p[i], e)) e = &f->p[i];
    if (e->prefix[0]) f->forgotten++;
    memset(e, 0, sizeof *e);
    memcpy(e->prefix, pre, len);
    return e;
}

/* The request a control_t carries (0: it does not decode, or names none); -1 for one of
 * this daemon's probes. */
static int request_of(const rt_foreign *f, const uint8_t *data, size_t len)
{
    static lag_wire_control m; /* large: not on the stack of a handler */
    if (lag_wire_decode_control(data, len, LAG_WIRE_MAX_JOINTS, &m) != LAG_WIRE_OK) return 0;
    for (int i = 0; i < RT_FOREIGN_STAMPS; i++)
        if (f->stamp[i] && m.utime == f->stamp[i] && m.request == LAGSIM_CONTROL_T_DESCRIBE)
            return -1;
    return m.request > 0 && m.request < RT_FOREIGN_REQUESTS ? m.request : 0;
}

rt_foreign_prefix *rt_foreign_request(rt_foreign *f, const char *channel, const char *own,
                                      bool state_port, const uint8_t *data, size_t len)
{
    bool mine = !strcmp(channel, own);
    if (mine && !state_port) return NULL; /* the loop's */
    size_t n = prefix_len(channel, lag_bus_suffix(LAG_BUS_CONTROL));
    int r = n ? request_of(f, data, len) : -1;
    if (r < 0) return NULL;
    if (mine) {
        f->own_state_port[r]++;
        f->own_state_port_total++;
        return NULL;
    }
    rt_foreign_prefix *e = entry(f, channel, n);
    e->requests[r]++;
    e->total++;
    e->state_port |= state_port;
    e->heard = ++f->clock;
    return e->probed_ns || e->has_plant ? NULL : e;
}

void rt_foreign_probed(rt_foreign *f, rt_foreign_prefix *e, int64_t now, int64_t stamp)
{
    e->probed_ns = now > 0 ? now : 1;
    f->stamp[f->stamp_next] = stamp;
    f->stamp_next = (f->stamp_next + 1) % RT_FOREIGN_STAMPS;
}

bool rt_foreign_unanswered(const rt_foreign_prefix *e, int64_t now)
{
    return e->prefix[0] && !e->has_plant && e->probed_ns &&
           now - e->probed_ns >= RT_FOREIGN_ANSWER_NS;
}

void rt_foreign_scene(rt_foreign *f, const char *channel, const char *own)
{
    size_t n = prefix_len(channel, lag_bus_suffix(LAG_BUS_SCENE));
    rt_foreign_prefix *e = n && strcmp(channel, own) ? find(f, channel, n) : NULL;
    if (e) e->has_plant = true; /* only a prefix asked: scenes alone fill no slot */
}

void rt_foreign_copy(rt_foreign *to, const rt_foreign *from) { *to = *from; }

const rt_foreign_prefix *rt_foreign_find(const rt_foreign *f, const char *prefix)
{
    for (int i = 0; i < RT_FOREIGN_MAX; i++)
        if (f->p[i].prefix[0] && !strcmp(f->p[i].prefix, prefix)) return &f->p[i];
    return NULL;
}
