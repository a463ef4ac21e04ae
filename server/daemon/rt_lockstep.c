/*
 * Lockstep's bookkeeping (rt_lockstep.h). While a state is waited on and no answer to it
 * has come, the same state goes out again, byte for byte (utime included), lockstep_retry
 * after it was published, then at gaps that double up to retry_cap_ns (a sixteenth of
 * lockstep_timeout: as many more chances before it), so that a state or a command lost on
 * the way costs a retry instead of a timeout, and a controller that thinks long per state
 * gets a copy every 62.5 ms at most (default scene), not one per lockstep_retry. Once any
 * command for that sim_time arrived (applied or rejected) the controller has the state: no
 * more copies. A state is known by its generation and sim time (every run starts again
 * at sim time 0). A controller answers each state once and a copy of it with the same
 * answer; a second answer to a state already answered is ignored (commands_ignored), so
 * the run does not depend on how many copies arrived.
 */
#include "rt_lockstep.h"
#include "rt_pace.h"

void rt_lockstep_init(rt_lockstep *l, double timeout_s, double retry_s)
{
    l->wait_ns = rt_ns_from_s(timeout_s);
    /* a retry at most every millisecond (a scene built in code may say 0) */
    l->retry_ns = retry_s > 0 ? rt_clamp_ns(retry_s * 1e9, RT_RETRY_NS_MIN, INT64_MAX)
                              : INT64_MAX;
    l->retry_cap_ns = l->wait_ns / 16 > l->retry_ns ? l->wait_ns / 16 : l->retry_ns;
}

void rt_lockstep_published(rt_lockstep *l, int64_t gen, double t, int64_t now)
{
    l->waiting = true;
    l->answered = false;
    l->waiting_time = t;
    l->waiting_gen = gen;
    l->wait_start_ns = now;
    l->answer_heard = false;
    l->retry_gap_ns = l->retry_ns;
    l->next_retry_ns = rt_sat_add(now, l->retry_gap_ns);
}

bool rt_lockstep_timed_out(const rt_lockstep *l, int64_t now)
{
    return now - l->wait_start_ns >= l->wait_ns;
}

bool rt_lockstep_retry(rt_lockstep *l, int64_t now)
{
    if (now < l->next_retry_ns || l->answer_heard) return false;
    int64_t cap = l->retry_cap_ns;
    l->retry_gap_ns = l->retry_gap_ns > cap / 2 ? cap : 2 * l->retry_gap_ns;
    l->next_retry_ns = rt_sat_add(now, l->retry_gap_ns);
    return true;
}

bool rt_lockstep_is_waited(const rt_lockstep *l, int64_t gen, double t)
{
    return l->waiting && gen == l->waiting_gen && t == l->waiting_time;
}

void rt_lockstep_heard(rt_lockstep *l, int64_t gen, double t)
{
    if (rt_lockstep_is_waited(l, gen, t)) l->answer_heard = true;
}

void rt_lockstep_answer(rt_lockstep *l, int64_t gen, double t, int64_t now)
{
    if (!rt_lockstep_is_waited(l, gen, t)) return;
    l->answered_ns = now;
    l->answered = true;
    l->answered_time = t;
    l->answered_gen = gen;
    l->have_answered = true;
}

bool rt_lockstep_repeated(const rt_lockstep *l, int64_t gen, double t)
{
    bool waited_on = rt_lockstep_is_waited(l, gen, t);
    return (waited_on && l->answered) ||
           (!waited_on && l->have_answered && t == l->answered_time && gen == l->answered_gen);
}
