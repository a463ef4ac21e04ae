/* The sim's queue of events (lag_sim.events): recorded by the step and the effects,
 * drained by lag_sim_poll_event. A leaf of the core. */
#include <math.h>
#include <string.h>
#include "core_internal.h"

void lag_sim_record_event(lag_sim *s, lag_event_kind kind, int joint, double t, double value)
{
    int cap = (int)(sizeof s->events / sizeof s->events[0]);
    LAG_ASSERT(s->n_events >= 0 && s->n_events <= cap);
    if (s->n_events >= cap) {
        s->events_dropped++;
        return;
    }
    lag_event *ev = &s->events[s->n_events++];
    ev->kind = kind;
    ev->joint = joint;
    ev->t = t;
    ev->value = isfinite(value) ? value : 0.0;
}

bool lag_sim_poll_event(lag_sim *s, lag_event *ev)
{
    if (s->n_events == 0) return false;
    *ev = s->events[0];
    memmove(&s->events[0], &s->events[1], sizeof(lag_event) * (size_t)(s->n_events - 1));
    s->n_events--;
    return true;
}
