/*
 * lagsim_client.hpp does what its header says, on a memq:// handle fed messages encoded
 * by the wire module (the bus's path, lag_client_feed):
 *   - errors are lagsim::Error with the library's code: a bad prefix (LAG_ERR_ARG), no
 *     scene in time (LAG_TIMEOUT), a command of mismatched sizes or a NaN effort
 *     (LAG_ERR_ARG, the library's message), a status field that does not exist;
 *   - nothing in time is no error: wait_state gives std::nullopt;
 *   - a callback's exception never crosses the C library: it comes out, of its own type,
 *     from the next call that runs callbacks, once;
 *   - a Scene handed to a callback is a view; a copy of it owns its own and outlives it;
 *   - State, Reference, the scene's and the status's fields read as the C library's;
 *   - Scene::mass and Scene::bias are the manipulator's M(q) and C(q, qd) qd + g(q) of
 *     docs/models.md (written out here), in vectors and in arrays; a scene without its
 *     parameters, or q of the wrong size, is Error LAG_ERR_ARG naming what is missing;
 *   - reference_of(state): the latest reference only when its generation and sim_time are
 *     the state's (a lost one, or one of another generation at the same sim_time: none);
 *   - a Controller's run ends: on silence after its timeout (heard() moves with every
 *     message kept, not with a dropped one), on the daemon's stop event, after its duration;
 *     and its state is returned once.
 *
 * usage: test_client_hpp   (exit 0 when every check holds)
 */
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "lagsim_client.hpp"
#include "lagsim_wire.h"

namespace {

int failures = 0;

void check(bool ok, const std::string &what)
{
    std::printf("%s: %s\n", ok ? "ok  " : "FAIL", what.c_str());
    failures += !ok;
}

/* The code of the lagsim::Error f throws (LAG_OK if none), its message in *msg. */
template <class F> lag_result error_of(F f, std::string *msg = nullptr)
{
    try {
        f();
    } catch (const lagsim::Error &e) {
        if (msg) *msg = e.what();
        return e.code();
    }
    return LAG_OK;
}

/* Encodes message m of type t and feeds it to c on <FED>_<suffix>. */
void feed(lagsim::Client &c, lag_wire_type t, const void *m, const char *suffix)
{
    unsigned char buf[LAG_WIRE_BUF_SIZE];
    int n = lag_wire_encode(t, m, buf, sizeof buf);
    std::string ch = std::string("FED_") + suffix;
    if (n <= 0 || lag_client_feed(c.get(), ch.c_str(), buf, static_cast<size_t>(n)) != LAG_OK)
        check(false, "feeding a " + std::string(lag_wire_type_name(t)));
}

void feed_scene(lagsim::Client &c, bool whole = false)
{
    lag_wire_scene s;
    std::memset(&s, 0, sizeof s);
    std::strcpy(s.model, "manipulator");
    std::strcpy(s.prefix, "FED");
    std::strcpy(s.mode, "lockstep");
    s.num_params = 2;
    std::strcpy(s.param_name[0], "m1");
    std::strcpy(s.param_name[1], "m2");
    s.param_value[0] = 2.0;
    s.param_value[1] = 1.25;
    s.num_joints = 2;
    std::strcpy(s.joint_name[0], "q1");
    std::strcpy(s.joint_name[1], "q2");
    s.actuated[0] = s.actuated[1] = true;
    s.control_period = 0.01;
    if (whole) { /* every parameter of the manipulator: m1, m2, l1, I1, I2, g */
        const char *more[] = {"l1", "I1", "I2", "g"};
        const double v[] = {0.3, 0.02, 0.05, 9.81};
        for (int i = 0; i < 4; i++) {
            std::strcpy(s.param_name[2 + i], more[i]);
            s.param_value[2 + i] = v[i];
        }
        s.num_params = 6;
        s.generation = 1;
    }
    feed(c, LAG_WIRE_SCENE, &s, "SCENE");
}

void feed_state(lagsim::Client &c, double t)
{
    lag_wire_joint_state s;
    std::memset(&s, 0, sizeof s);
    s.sim_time = t;
    s.step = static_cast<int64_t>(t * 1000);
    s.num_joints = 2;
    std::strcpy(s.name[0], "q1");
    std::strcpy(s.name[1], "q2");
    s.position[0] = 0.25;
    s.position[1] = 0.5;
    feed(c, LAG_WIRE_JOINT_STATE, &s, "STATE");
}

void errors()
{
    check(error_of([] { lagsim::Client c(""); }) == LAG_ERR_ARG, "an empty prefix: LAG_ERR_ARG");
    check(error_of([] { lagsim::Client c(std::string(64, 'P')); }) == LAG_ERR_ARG,
          "a prefix of 64 bytes: LAG_ERR_ARG");
    lagsim::Client c("FED", "memq://");
    std::string msg;
    lag_result rc = error_of([&] { c.wait_scene(0.3); }, &msg);
    check(rc == LAG_TIMEOUT && msg.find("FED_SCENE") != std::string::npos,
          "no scene in time: LAG_TIMEOUT naming the channel (" + msg + ")");
    check(!c.wait_state(0.05), "no state in time: std::nullopt, no exception");
    check(!c.latest_state() && !c.latest_reference() && !c.latest_status(),
          "nothing latest before anything came");
    check(error_of([&] { c.send_command(0.0, {"q1", "q2"}, {1.0}); }) == LAG_ERR_ARG,
          "two names, one effort: LAG_ERR_ARG");
    rc = error_of([&] { c.send_command(0.0, {"q1"}, {NAN}); }, &msg);
    check(rc == LAG_ERR_ARG && msg.find("NaN") != std::string::npos,
          "a NaN effort: LAG_ERR_ARG with the library's message (" + msg + ")");
    check(error_of([&] { c.step(0); }) == LAG_ERR_ARG, "step(0): LAG_ERR_ARG");
}

void messages()
{
    lagsim::Client c("FED", "memq://");
    std::optional<lagsim::Scene> kept;
    int scenes = 0;
    c.on_scene([&](const lagsim::Scene &sc) {
        scenes++;
        kept = sc; /* a copy of the view: its own handle */
    });
    feed_scene(c);
    check(scenes == 1 && kept && kept->model() == "manipulator" && kept->param("m2") == 1.25 &&
              kept->joint("q2") == 1 && kept->actuated(1) &&
              kept->joints() == std::vector<std::string>{"q1", "q2"},
          "on_scene's view copied: model, parameter, joints as sent");
    check(error_of([&] { kept->param("m9"); }) == LAG_ERR_ARG && !kept->find_param("m9"),
          "a parameter the scene has not: Error, find_param empty");
    lagsim::Scene scene = c.wait_scene(1.0);
    check(scene.control_period() == 0.01 && scene.mode() == "lockstep",
          "wait_scene: the scene that came");

    feed_state(c, 0.5);
    std::optional<lagsim::State> st = c.wait_state(1.0);
    check(st && st->sim_time == 0.5 && st->joint("q2") == 1 && st->position[1] == 0.5 &&
              st->positions() == std::vector<double>{0.25, 0.5} &&
              st->names() == std::vector<std::string>{"q1", "q2"},
          "wait_state: the state, its joints and positions");
    check(!c.wait_state(0.05), "each state once: not returned again");

    lag_wire_status s;
    std::memset(&s, 0, sizeof s);
    s.rtf = 1.5;
    std::strcpy(s.run_state, "paused");
    feed(c, LAG_WIRE_STATUS, &s, "STATUS");
    std::optional<lagsim::Status> status = c.latest_status();
    check(status && status->number("rtf") == 1.5 && status->run_state() == "paused" &&
              status->fields().size() == static_cast<size_t>(lag_client_status_fields()),
          "the status's fields by name");
    check(error_of([&] { status->number("no_such_field"); }) == LAG_ERR_ARG &&
              error_of([&] { status->text("rtf"); }) == LAG_ERR_ARG,
          "a status field that is not there, or not a text: Error");
}

void dynamics()
{
    lagsim::Client c("FED", "memq://");
    feed_scene(c); /* m1 and m2 only */
    lagsim::Scene part = *c.latest_scene();
    std::string msg;
    bool refused = error_of([&] { part.mass({0.1, 0.5}); }, &msg) == LAG_ERR_ARG &&
                   msg.find("no parameter l1") != std::string::npos;
    check(refused, "a scene without the model's parameters: Error naming one (" + msg + ")");
    feed_scene(c, true);
    lagsim::Scene sc = *c.latest_scene();
    const double m1 = 2.0, m2 = 1.25, l1 = 0.3, I1 = 0.02, I2 = 0.05, g = 9.81;
    const double q1 = 0.7, q2 = 0.45, q1d = -1.3, q2d = 0.8;
    std::vector<double> M = sc.mass({q1, q2}), h = sc.bias({q1, q2}, {q1d, q2d});
    const double Mw[4] = {m1 * l1 * l1 + I1 + I2 + m2 * q2 * q2, 0, 0, m2};
    const double hw[2] = {2 * m2 * q2 * q1d * q2d + (m1 * l1 + m2 * q2) * g * std::cos(q1),
                          -m2 * q2 * q1d * q1d + m2 * g * std::sin(q1)};
    bool ok = M.size() == 4 && h.size() == 2;
    for (int i = 0; ok && i < 4; i++) ok = std::fabs(M[i] - Mw[i]) <= 1e-14 * 2;
    for (int i = 0; ok && i < 2; i++) ok = std::fabs(h[i] - hw[i]) <= 1e-13 * 20;
    check(ok, "mass and bias: docs/models.md's M(q) and C(q, qd) qd + g(q) of the manipulator");
    double Ma[4], ha[2];
    const double q[2] = {q1, q2}, qd[2] = {q1d, q2d};
    sc.mass(2, q, Ma);
    sc.bias(2, q, qd, ha);
    check(std::equal(Ma, Ma + 4, M.begin()) && std::equal(ha, ha + 2, h.begin()),
          "the array forms: the same numbers");
    refused = error_of([&] { sc.mass({q1, q2, 0.0}); }, &msg) == LAG_ERR_ARG &&
              msg.find("2 coordinates") != std::string::npos &&
              error_of([&] { sc.bias({q1, q2}, {q1d}); }) == LAG_ERR_ARG &&
              error_of([&] { sc.bias({q1, NAN}, {q1d, q2d}); }) == LAG_ERR_ARG;
    check(refused, "q of another size, qd of another size than q, a NaN: Error (" + msg + ")");
}

void feed_reference(lagsim::Client &c, int64_t generation, double t)
{
    lag_wire_reference r;
    std::memset(&r, 0, sizeof r);
    r.generation = generation;
    r.sim_time = t;
    r.num_joints = 1;
    std::strcpy(r.name[0], "q1");
    r.r[0] = 0.125;
    feed(c, LAG_WIRE_REFERENCE, &r, "REFERENCE");
}

void references()
{
    lagsim::Client c("FED", "memq://");
    feed_scene(c);
    feed_reference(c, 0, 0.5);
    feed_state(c, 0.5);
    std::optional<lagsim::State> st = c.wait_state(1.0);
    std::optional<lagsim::Reference> ref = st ? c.reference_of(*st) : std::nullopt;
    check(ref && ref->r[ref->joint("q1")] == 0.125 && ref->sim_time == 0.5,
          "reference_of: the state's own reference (its generation and sim_time)");
    feed_state(c, 0.6); /* its reference lost */
    st = c.wait_state(1.0);
    check(st && !c.reference_of(*st) && c.latest_reference(), "reference_of: a lost one is none");
    feed_reference(c, 7, 0.7); /* another generation's, at the sim_time of the next state */
    feed_state(c, 0.7);
    st = c.wait_state(1.0);
    check(st && st->generation == 0 && !c.reference_of(*st),
          "reference_of: another generation's at the same sim_time is none");
}

void controller()
{
    lagsim::Controller::Options o;
    o.url = "memq://";
    o.timeout = 0.3;
    {
        lagsim::Controller ctl("FED", o);
        double t0 = lagsim::now(), h0 = ctl.client().heard();
        unsigned char junk[3] = {1, 2, 3};
        lag_client_feed(ctl.client().get(), "FED_STATE", junk, sizeof junk); /* dropped */
        bool quiet = ctl.client().heard() == h0;
        feed_scene(ctl.client());
        bool moved = ctl.client().heard() > h0;
        std::optional<lagsim::State> st = ctl.next();
        double waited = lagsim::now() - t0;
        check(quiet && moved && !st && ctl.end() == "silence" && waited >= 0.3 && waited < 3.0 &&
                  !ctl.next(),
              "silence: heard() moves with a message kept, not a dropped one; next() ends after "
              "the timeout (" + std::to_string(waited) + " s), end silence, and stays ended");
    }
    {
        lagsim::Controller ctl("FED", o);
        feed_scene(ctl.client());
        feed_state(ctl.client(), 0.5);
        std::optional<lagsim::State> st = ctl.next();
        lag_wire_event ev;
        std::memset(&ev, 0, sizeof ev);
        std::strcpy(ev.kind, "stop");
        feed(ctl.client(), LAG_WIRE_EVENT, &ev, "EVENT");
        double t0 = lagsim::now();
        std::optional<lagsim::State> again = ctl.next();
        check(st && st->sim_time == 0.5 && !again && ctl.end() == "stop" &&
                  lagsim::now() - t0 < 0.3 && ctl.states() == 1,
              "stop: the state once, then the stop event ends the run before any silence");
    }
    {
        o.duration = 0.5;
        lagsim::Controller ctl("FED", o);
        feed_scene(ctl.client());
        feed_state(ctl.client(), 0.0);
        bool first = ctl.next().has_value();
        feed_state(ctl.client(), 0.5);
        bool second = ctl.next().has_value();
        check(first && second && !ctl.next() && ctl.end() == "duration",
              "duration: 0.5 s of sim time from the first state ends the run");
    }
}

void callback_exceptions()
{
    lagsim::Client c("FED", "memq://");
    int events = 0;
    c.on_event([&](const lagsim::Event &ev) {
        events++;
        if (ev.is("boom")) throw std::domain_error("boom at " + std::to_string(ev.sim_time));
    });
    lag_wire_event e;
    std::memset(&e, 0, sizeof e);
    e.sim_time = 2.5;
    std::strcpy(e.kind, "boom");
    feed(c, LAG_WIRE_EVENT, &e, "EVENT"); /* the C library runs the callback here */
    bool caught = false;
    try {
        c.handle(0);
    } catch (const std::domain_error &x) {
        caught = std::string(x.what()) == "boom at 2.500000";
    }
    check(events == 1 && caught, "a callback's exception comes out of the next handle(), its "
                                 "own type and message");
    bool again = false;
    try {
        c.handle(0);
    } catch (...) {
        again = true;
    }
    check(!again, "... once");
    std::strcpy(e.kind, "set");
    feed(c, LAG_WIRE_EVENT, &e, "EVENT");
    check(events == 2, "callbacks run again afterwards");
}

} // namespace

int main()
{
    check(lagsim::version() == LAGSIM_VERSION_NUMBER && lagsim::abi() == LAGSIM_CLIENT_ABI,
          "version() and abi() are the header's");
    errors();
    messages();
    dynamics();
    references();
    controller();
    callback_exceptions();
    std::printf("%d failure(s)\n", failures);
    return failures ? 1 : 0;
}
