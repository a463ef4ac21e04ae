/*
 * lagsim client library for C++17: a header of RAII handles over the C library
 * (lagsim_client.h, liblagsim_client.so), as cppzmq's zmq.hpp is over libzmq and LCM's
 * lcm-cpp.hpp over lcm.h. The rules of the protocol (the plant's two URLs, DESCRIBE until
 * the scene comes, each state once, a copy answered with the same command, the
 * generation stamped on every command, a state held until its scene came, every message
 * decoded whole and bounded) are the C library's; this header only makes them C++:
 *
 *   lagsim::Client c("DIPC");                     // LCM's default URL; throws lagsim::Error
 *   lagsim::Scene sc = c.wait_scene(5.0);         // DESCRIBE until the scene comes
 *   while (auto st = c.wait_state(2.0)) {         // each state once, the newest
 *       double u = -k * st->position[st->joint("theta1")];
 *       c.send_command(*st, {"theta0"}, {u});     // answers this state
 *   }
 *
 * Build: c++ -std=c++17 my.cpp $(pkg-config --cflags --libs lagsim-client).
 *
 * Errors are exceptions: lagsim::Error, a std::runtime_error with the library's result
 * code (code(): a negative lag_result of lagsim/result.h) and its message. Nothing
 * arriving in time is no error: the waits return std::nullopt (wait_state) or throw
 * Error with code LAG_TIMEOUT only where a value must come (wait_scene, pick_plant).
 *
 * Callbacks are any callable (lambdas); they run inside handle() and the waits, in the
 * thread that calls them. An exception a callback throws never crosses the C library: it
 * is kept and thrown again, as it was, from the call that ran the callback.
 *
 * Threads: as in C, one Client is used by one thread at a time; Clients, discover() and
 * pick_plant() may be used from several threads at once.
 *
 * The types: State, Reference and Event are the C structs (fields as in lagsim_client.h:
 * st.sim_time, st.position[i], ...) with helpers; Scene and Status own a C handle (copies
 * are deep, a moved-from one is empty). Nothing here allocates per state: a State is a
 * plain struct, send_command builds its name array on the stack.
 */
#ifndef LAGSIM_CLIENT_HPP
#define LAGSIM_CLIENT_HPP

#include <csignal>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <functional>
#include <memory>
#include <new>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <signal.h>

#include "lagsim_client.h"

namespace lagsim {

/* An error of the client library: its result code and message. */
class Error : public std::runtime_error {
public:
    Error(lag_result code, const std::string &what) : std::runtime_error(what), code_(code) {}
    /* LAG_ERR_ARG, LAG_ERR_LCM, LAG_ERR_NOMEM, LAG_ERR_AMBIGUOUS, LAG_TIMEOUT, ... */
    lag_result code() const noexcept { return code_; }

private:
    lag_result code_;
};

namespace detail {
inline std::string describe(lag_result rc, const char *msg)
{
    const char *name = lag_result_name(rc);
    std::string s = name ? name : "lag_result " + std::to_string(static_cast<int>(rc));
    return s + ": " + (msg && *msg ? msg : lag_result_string(rc));
}
/* rc, or Error when it is an error (rc < 0) */
inline lag_result check(lag_result rc, const lag_client *c)
{
    if (rc < 0) throw Error(rc, describe(rc, c ? lag_client_errmsg(c) : nullptr));
    return rc;
}
} // namespace detail

/* The library's version as it runs (LAGSIM_VERSION_NUMBER at its build) and its ABI
 * number; the header's are LAGSIM_VERSION_NUMBER and LAGSIM_CLIENT_ABI. */
inline int version() { return lag_client_version(); }
inline int abi() { return lag_client_abi(); }
/* Wall clock (monotonic), s. */
inline double now() { return lag_client_now(); }

/* A state (lag_client_state: utime, sim_time, step, generation, num_joints, name[],
 * position[], velocity[], effort[]). */
struct State : lag_client_state {
    State() : lag_client_state() {}
    /* the index of joint `name`, or -1 */
    int joint(const std::string &n) const { return lag_client_state_joint(this, n.c_str()); }
    std::vector<std::string> names() const { return {name, name + num_joints}; }
    std::vector<double> positions() const { return {position, position + num_joints}; }
    std::vector<double> velocities() const { return {velocity, velocity + num_joints}; }
};

/* A reference (lag_client_reference: sim_time, step, generation, num_joints, name[], r[],
 * rdot[], rddot[]): what the joints with a reference follow at the state of that
 * generation and sim_time (Client::reference_of). */
struct Reference : lag_client_reference {
    Reference() : lag_client_reference() {}
    /* the index of joint `name`, or -1 (the scene gives it no reference) */
    int joint(const std::string &n) const { return lag_client_reference_joint(this, n.c_str()); }
};

/* An event (lag_client_event: utime, sim_time, step, value, kind, joint, detail). */
struct Event : lag_client_event {
    Event() : lag_client_event() {}
    bool is(const char *k) const { return std::string(kind) == k; }
};

/* A plant heard on the bus (lag_client_plant). */
struct Plant : lag_client_plant {
    Plant() : lag_client_plant() {}
};

/* The scene description: owns a lag_client_scene (or, in a callback, shows the
 * library's during the call; a copy of it owns its own). */
class Scene {
public:
    Scene() : p_(lag_client_scene_new()), own_(true)
    {
        if (!p_) throw std::bad_alloc();
    }
    ~Scene()
    {
        if (own_) lag_client_scene_free(p_);
    }
    Scene(const Scene &o) : Scene() { lag_client_scene_copy(p_, o.p_); }
    Scene &operator=(const Scene &o)
    {
        if (this != &o) {
            Scene t(o);
            swap(t);
        }
        return *this;
    }
    Scene(Scene &&o) noexcept : p_(std::exchange(o.p_, nullptr)), own_(std::exchange(o.own_, false)) {}
    Scene &operator=(Scene &&o) noexcept
    {
        Scene t(std::move(o));
        swap(t);
        return *this;
    }
    void swap(Scene &o) noexcept
    {
        std::swap(p_, o.p_);
        std::swap(own_, o.own_);
    }
    /* a view of the library's scene, valid while `p` is (callbacks) */
    static Scene view(const lag_client_scene *p) { return Scene(const_cast<lag_client_scene *>(p)); }

    std::string model() const { return lag_client_scene_model(p_); }
    std::string prefix() const { return lag_client_scene_prefix(p_); }
    int64_t generation() const { return lag_client_scene_generation(p_); }
    std::string mode() const { return lag_client_scene_mode(p_); }
    std::string integrator() const { return lag_client_scene_integrator(p_); }
    std::string effects() const { return lag_client_scene_effects(p_); }
    double dt() const { return lag_client_scene_dt(p_); }
    double control_period() const { return lag_client_scene_control_period(p_); }
    double rate() const { return lag_client_scene_rate(p_); }
    double command_timeout() const { return lag_client_scene_command_timeout(p_); }

    std::vector<std::string> joints() const
    {
        std::vector<std::string> v;
        for (int i = 0; i < lag_client_scene_num_joints(p_); i++)
            v.emplace_back(lag_client_scene_joint_name(p_, i));
        return v;
    }
    /* the index of joint `name`, or -1 */
    int joint(const std::string &name) const { return lag_client_scene_joint(p_, name.c_str()); }
    bool actuated(int i) const { return lag_client_scene_actuated(p_, i); }
    double initial_q(int i) const { return lag_client_scene_initial_q(p_, i); }
    double initial_qd(int i) const { return lag_client_scene_initial_qd(p_, i); }
    bool limit_on(int i) const { return lag_client_scene_limit_on(p_, i); }
    double limit_lower(int i) const { return lag_client_scene_limit_lower(p_, i); }
    double limit_upper(int i) const { return lag_client_scene_limit_upper(p_, i); }

    std::vector<std::string> param_names() const
    {
        std::vector<std::string> v;
        for (int i = 0; i < lag_client_scene_num_params(p_); i++)
            v.emplace_back(lag_client_scene_param_name(p_, i));
        return v;
    }
    /* parameter `name`; Error (LAG_ERR_ARG) when the scene has none of that name */
    double param(const std::string &name) const
    {
        double v = lag_client_scene_param(p_, name.c_str());
        if (std::isnan(v))
            throw Error(LAG_ERR_ARG, "scene " + model() + " has no parameter " + name);
        return v;
    }
    std::optional<double> find_param(const std::string &name) const
    {
        double v = lag_client_scene_param(p_, name.c_str());
        return std::isnan(v) ? std::nullopt : std::optional<double>(v);
    }

    /* The model's dynamics with this scene's parameters (lag_client_model_mass,
     * lag_client_model_bias; docs/clients.md): M(q) qdd + h(q, qd) = tau + the effects'
     * forces, h = C(q, qd) qd + g(q), the effects (damping, friction, springs, limits, ...)
     * not included. q and qd in the scene's joint order (a state's), as many as its
     * joints; Error (LAG_ERR_ARG) for another number, a non-finite value, or a scene whose
     * model or parameters the library cannot use. mass: n*n, row-major (M[i*n + j]). */
    std::vector<double> mass(const std::vector<double> &q) const
    {
        std::vector<double> M(q.size() * q.size());
        mass(static_cast<int>(q.size()), q.data(), M.data());
        return M;
    }
    std::vector<double> bias(const std::vector<double> &q, const std::vector<double> &qd) const
    {
        if (q.size() != qd.size())
            throw Error(LAG_ERR_ARG, "LAG_ERR_ARG: bias: q and qd of different sizes");
        std::vector<double> h(q.size());
        bias(static_cast<int>(q.size()), q.data(), qd.data(), h.data());
        return h;
    }
    /* The same into arrays of the caller's (n and n*n doubles): no allocation. */
    void mass(int n, const double *q, double *M) const
    {
        char err[256] = "";
        lag_result rc = lag_client_model_mass(p_, n, q, M, err, sizeof err);
        if (rc != LAG_OK) throw Error(rc, detail::describe(rc, err));
    }
    void bias(int n, const double *q, const double *qd, double *h) const
    {
        char err[256] = "";
        lag_result rc = lag_client_model_bias(p_, n, q, qd, h, err, sizeof err);
        if (rc != LAG_OK) throw Error(rc, detail::describe(rc, err));
    }

    const lag_client_scene *get() const { return p_; }
    lag_client_scene *get() { return p_; }

private:
    explicit Scene(lag_client_scene *p) : p_(p), own_(false) {}
    lag_client_scene *p_;
    bool own_;
};

/* The daemon's status (status_t), its fields by their .lcm names: owns a
 * lag_client_status (or, in a callback, shows the library's during the call). */
class Status {
public:
    Status() : p_(lag_client_status_new()), own_(true)
    {
        if (!p_) throw std::bad_alloc();
    }
    ~Status()
    {
        if (own_) lag_client_status_free(p_);
    }
    Status(const Status &o) : Status() { lag_client_status_copy(p_, o.p_); }
    Status &operator=(const Status &o)
    {
        if (this != &o) {
            Status t(o);
            swap(t);
        }
        return *this;
    }
    Status(Status &&o) noexcept : p_(std::exchange(o.p_, nullptr)), own_(std::exchange(o.own_, false)) {}
    Status &operator=(Status &&o) noexcept
    {
        Status t(std::move(o));
        swap(t);
        return *this;
    }
    void swap(Status &o) noexcept
    {
        std::swap(p_, o.p_);
        std::swap(own_, o.own_);
    }
    static Status view(const lag_client_status *p) { return Status(const_cast<lag_client_status *>(p)); }

    /* a numeric field (integers exact to 2^53, booleans 0/1); Error when there is none of
     * that name */
    double number(const std::string &field) const
    {
        double v = lag_client_status_number(p_, field.c_str());
        if (std::isnan(v)) throw Error(LAG_ERR_ARG, "status_t has no numeric field " + field);
        return v;
    }
    /* a text field; Error when there is none of that name */
    std::string text(const std::string &field) const
    {
        const char *t = lag_client_status_text(p_, field.c_str());
        if (!t) throw Error(LAG_ERR_ARG, "status_t has no text field " + field);
        return t;
    }
    double sim_time() const { return number("sim_time"); }
    std::string run_state() const { return text("run_state"); }
    /* the names of its fields, in the .lcm file's order */
    static std::vector<std::string> fields()
    {
        std::vector<std::string> v;
        for (int i = 0; i < lag_client_status_fields(); i++)
            v.emplace_back(lag_client_status_field_name(i));
        return v;
    }

    const lag_client_status *get() const { return p_; }
    lag_client_status *get() { return p_; }

private:
    explicit Status(lag_client_status *p) : p_(p), own_(false) {}
    lag_client_status *p_;
    bool own_;
};

/* A connection to one plant (lag_client): its URL (empty: LCM's default, honouring
 * LCM_DEFAULT_URL) and channel prefix; Error LAG_ERR_ARG for a prefix that is empty or
 * 64 bytes or more, LAG_ERR_LCM when LCM cannot be opened on the URL. Movable, not
 * copyable. */
class Client {
public:
    explicit Client(const std::string &prefix, const std::string &url = "")
        : prefix_(prefix), url_(url), cb_(std::make_unique<Callbacks>())
    {
        if (prefix.empty() || prefix.size() >= LAG_CLIENT_NAME_LEN)
            throw Error(LAG_ERR_ARG, "LAG_ERR_ARG: a prefix of 1 to 63 characters, not '" + prefix + "'");
        char err[256] = "";
        c_.reset(lag_client_create(url.empty() ? nullptr : url.c_str(), prefix.c_str(), err,
                                   sizeof err));
        if (!c_) throw Error(LAG_ERR_LCM, detail::describe(LAG_ERR_LCM, err));
    }

    /* The scene (DESCRIBE at once and every 0.25 s until it comes); Error with LAG_TIMEOUT
     * when none came within timeout_s, its message naming the plants heard on the bus
     * instead (lag_client_plants_instead, listening 1 s more: a misspelt prefix). */
    Scene wait_scene(double timeout_s)
    {
        Scene sc;
        if (!try_wait_scene(timeout_s, sc)) throw no_scene(timeout_s);
        return sc;
    }
    /* The same without the Error: false when no scene came within timeout_s. */
    bool try_wait_scene(double timeout_s, Scene &sc)
    {
        return run(lag_client_wait_scene(c_.get(), timeout_s, sc.get())) == LAG_OK;
    }
    /* The Error of no scene within waited_s: what the bus has instead of this prefix. */
    Error no_scene(double waited_s) const
    {
        char instead[1500] = "";
        lag_client_plants_instead(url_.empty() ? nullptr : url_.c_str(), prefix_.c_str(), 1.0,
                                  instead, sizeof instead);
        char head[160];
        std::snprintf(head, sizeof head, "no scene description on %s_SCENE within %g s: ",
                      prefix_.c_str(), waited_s);
        return Error(LAG_TIMEOUT, detail::describe(LAG_TIMEOUT, (head + std::string(instead)).c_str()));
    }
    const std::string &prefix() const { return prefix_; }
    const std::string &url() const { return url_; }
    /* The newest state not yet returned, or nullopt when none came within timeout_s. */
    std::optional<State> wait_state(double timeout_s)
    {
        State st;
        if (run(lag_client_wait_state(c_.get(), timeout_s, &st, sizeof st)) != LAG_OK)
            return std::nullopt;
        return st;
    }
    /* Handles at most one message (waiting up to timeout_ms): true when one was. */
    bool handle(int timeout_ms) { return run(lag_client_handle(c_.get(), timeout_ms)) == LAG_OK; }

    std::optional<State> latest_state() const
    {
        State st;
        return lag_client_latest_state(c_.get(), &st, sizeof st) ? std::optional<State>(st)
                                                                 : std::nullopt;
    }
    std::optional<Reference> latest_reference() const
    {
        Reference r;
        return lag_client_latest_reference(c_.get(), &r, sizeof r) ? std::optional<Reference>(r)
                                                                   : std::nullopt;
    }
    /* the reference of state st (the latest one, when its generation and sim_time are
     * st's), or std::nullopt: lost, or a scene without a reference */
    std::optional<Reference> reference_of(const State &st) const
    {
        Reference r;
        return lag_client_reference_of(c_.get(), &st, &r, sizeof r) ? std::optional<Reference>(r)
                                                                     : std::nullopt;
    }
    /* the scene of the latest state's generation */
    std::optional<Scene> latest_scene() const
    {
        Scene sc;
        return lag_client_latest_scene(c_.get(), sc.get()) ? std::optional<Scene>(std::move(sc))
                                                           : std::nullopt;
    }
    std::optional<Status> latest_status() const
    {
        Status s;
        return lag_client_latest_status(c_.get(), s.get()) ? std::optional<Status>(std::move(s))
                                                           : std::nullopt;
    }

    /* Efforts for the joints named, answering the state at sim_time (stamped with the
     * latest state's generation). Error (LAG_ERR_ARG) for more than 8 joints, sizes that
     * differ, a non-finite effort or a name of 64 bytes or more. */
    void send_command(double sim_time, const std::vector<std::string> &names,
                      const std::vector<double> &effort)
    {
        if (names.size() != effort.size() || names.size() > LAG_CLIENT_MAX_JOINTS)
            throw Error(LAG_ERR_ARG, "send_command: " + std::to_string(names.size()) +
                                         " names, " + std::to_string(effort.size()) +
                                         " efforts (equal, at most 8)");
        const char *n[LAG_CLIENT_MAX_JOINTS];
        for (size_t i = 0; i < names.size(); i++) n[i] = names[i].c_str();
        detail::check(lag_client_send_command(c_.get(), sim_time, static_cast<int>(names.size()),
                                              n, effort.data()),
                      c_.get());
    }
    void send_command(const State &st, const std::vector<std::string> &names,
                      const std::vector<double> &effort)
    {
        send_command(st.sim_time, names, effort);
    }

    /* Control requests (lagsim_client.h says what each does). */
    void pause() { detail::check(lag_client_pause(c_.get()), c_.get()); }
    void resume() { detail::check(lag_client_resume(c_.get()), c_.get()); }
    void step(int64_t periods) { detail::check(lag_client_step(c_.get(), periods), c_.get()); }
    void reset() { detail::check(lag_client_reset(c_.get()), c_.get()); }
    void reset_scene() { detail::check(lag_client_reset_scene(c_.get()), c_.get()); }
    /* flags: an OR of LAG_CLIENT_RESET_SCENE and LAG_CLIENT_RESET_WAIT */
    void reset_with(int flags) { detail::check(lag_client_reset_with(c_.get(), flags, 0, nullptr, nullptr), c_.get()); }
    void reset_to(const std::vector<double> &q, const std::vector<double> &qd, int flags = 0)
    {
        if (q.size() != qd.size())
            throw Error(LAG_ERR_ARG, "reset_to: q and qd of different sizes");
        detail::check(lag_client_reset_with(c_.get(), flags, static_cast<int>(q.size()), q.data(),
                                            qd.data()),
                      c_.get());
    }
    void request_status() { detail::check(lag_client_request_status(c_.get()), c_.get()); }
    void request_describe() { detail::check(lag_client_request_describe(c_.get()), c_.get()); }
    void set(const std::string &key, const std::string &value)
    {
        detail::check(lag_client_set(c_.get(), key.c_str(), value.c_str()), c_.get());
    }
    void kick(const std::string &joint, double impulse, double duration = 0.0)
    {
        detail::check(lag_client_kick(c_.get(), joint.c_str(), impulse, duration), c_.get());
    }

    lag_client_counters counters() const
    {
        lag_client_counters k{};
        lag_client_get_counters(c_.get(), &k, sizeof k);
        return k;
    }
    /* when the last message from the daemon was kept, on now()'s clock (lag_client_heard) */
    double heard() const { return lag_client_heard(c_.get()); }
    /* for poll()/select(): when readable, handle(0) */
    int fileno() const { return lag_client_fileno(c_.get()); }
    lag_client *get() const { return c_.get(); }

    /* Callbacks (an empty function removes one). */
    void on_state(std::function<void(const State &)> f)
    {
        cb_->state = std::move(f);
        lag_client_on_state(c_.get(), cb_->state ? &Callbacks::on_state : nullptr, cb_.get());
    }
    void on_reference(std::function<void(const Reference &)> f)
    {
        cb_->reference = std::move(f);
        lag_client_on_reference(c_.get(), cb_->reference ? &Callbacks::on_reference : nullptr,
                                cb_.get());
    }
    void on_event(std::function<void(const Event &)> f)
    {
        cb_->event = std::move(f);
        lag_client_on_event(c_.get(), cb_->event ? &Callbacks::on_event : nullptr, cb_.get());
    }
    void on_scene(std::function<void(const Scene &)> f)
    {
        cb_->scene = std::move(f);
        lag_client_on_scene(c_.get(), cb_->scene ? &Callbacks::on_scene : nullptr, cb_.get());
    }
    void on_status(std::function<void(const Status &)> f)
    {
        cb_->status = std::move(f);
        lag_client_on_status(c_.get(), cb_->status ? &Callbacks::on_status : nullptr, cb_.get());
    }

private:
    /* The callables, at an address that moves of the Client leave alone; the first
     * exception one threw, until the call that ran it returns. */
    struct Callbacks {
        std::function<void(const State &)> state;
        std::function<void(const Reference &)> reference;
        std::function<void(const Event &)> event;
        std::function<void(const Scene &)> scene;
        std::function<void(const Status &)> status;
        std::exception_ptr pending;

        template <class F> void guard(F &&f) noexcept
        {
            if (pending) return; /* the first one is thrown; the others are not run */
            try {
                f();
            } catch (...) {
                pending = std::current_exception();
            }
        }
        /* The structs the library passes are the ones State, Reference and Event derive
         * from without adding a member: a copy gives the callable the C++ type. */
        static void on_state(const lag_client_state *s, void *u)
        {
            auto *cb = static_cast<Callbacks *>(u);
            cb->guard([&] {
                State st;
                static_cast<lag_client_state &>(st) = *s;
                cb->state(st);
            });
        }
        static void on_reference(const lag_client_reference *r, void *u)
        {
            auto *cb = static_cast<Callbacks *>(u);
            cb->guard([&] {
                Reference ref;
                static_cast<lag_client_reference &>(ref) = *r;
                cb->reference(ref);
            });
        }
        static void on_event(const lag_client_event *e, void *u)
        {
            auto *cb = static_cast<Callbacks *>(u);
            cb->guard([&] {
                Event ev;
                static_cast<lag_client_event &>(ev) = *e;
                cb->event(ev);
            });
        }
        static void on_scene(const lag_client_scene *s, void *u)
        {
            auto *cb = static_cast<Callbacks *>(u);
            cb->guard([&] { cb->scene(Scene::view(s)); });
        }
        static void on_status(const lag_client_status *s, void *u)
        {
            auto *cb = static_cast<Callbacks *>(u);
            cb->guard([&] { cb->status(Status::view(s)); });
        }
    };
    /* A call that may have run callbacks: their exception first, then the call's error. */
    lag_result run(lag_result rc)
    {
        if (cb_->pending) std::rethrow_exception(std::exchange(cb_->pending, nullptr));
        return detail::check(rc, c_.get());
    }
    struct Destroy {
        void operator()(lag_client *c) const { lag_client_destroy(c); }
    };
    std::string prefix_, url_;
    std::unique_ptr<Callbacks> cb_;
    std::unique_ptr<lag_client, Destroy> c_;
};

/* A controller's run: a Client and the rules by which the run of every example controller
 * (C's lag_ctl, Python's, Lua's and Java's Controller) ends, so that a loop over next()
 * ends when the daemon stops, dies or falls silent:
 *
 *   lagsim::Controller ctl("DIPC");                   // ends: stop, silence, signal
 *   while (std::optional<lagsim::State> st = ctl.next()) {  // each state once, the newest
 *       double u = ...;                               // ctl.scene(): its scene
 *       ctl.send_command(*st, {"theta0"}, {u});       // answers it
 *   }
 *   // ctl.end(): "stop", "silence", "duration" or "signal"
 *
 * next() returns std::nullopt once the run has ended, and end() says why:
 *   "stop"      the daemon published its stop event (it ends a run: --duration, SIGINT);
 *   "silence"   nothing came from the daemon (no state, scene, status, event or
 *               reference) for Options::timeout wall seconds (default 5): a daemon killed,
 *               hung, or never started (a plant that waits or is paused publishes its
 *               status at realtime.status_hz, 5 Hz by default: it is not silent);
 *   "duration"  Options::duration s of sim time passed since the first state (0: never);
 *   "signal"    SIGINT or SIGTERM came (Options::signals, the default: the handlers are
 *               installed for the Controller's life and the previous ones put back after).
 * None of these is an error: the examples exit 0 for each. A client error (the bus
 * failing) is an Error thrown from next() or send_command().
 * Events reach ctl.on_event (ctl.client().on_event would replace the Controller's own). */
class Controller {
public:
    struct Options {
        std::string url;       /* the plant's LCM URL ("": the URL a host's directory names
                                * for the prefix, else LCM's default, LCM_DEFAULT_URL) */
        double timeout = 5.0;  /* wall s of silence that end the run (> 0) */
        double duration = 0.0; /* sim s from the first state that end the run (0: none) */
        bool signals = true;   /* SIGINT and SIGTERM end the run */
        bool locate = true;    /* url "": ask a host's directory first (lagsim::locate) */
    };

    explicit Controller(const std::string &prefix) : Controller(prefix, Options()) {}
    /* With Options::url "" (and locate), the plant's URL is the one a host's directory on
     * LCM's default bus names for prefix (lagsim::locate: 1 s at most), else LCM's
     * default; options().url says which ("" for the default), located() whether the
     * directory named it. */
    Controller(const std::string &prefix, const Options &o)
        : o_(o), located_(o.url.empty() && o.locate && locate_into(prefix, o_.url)),
          c_(prefix, o_.url)
    {
        if (!(o.timeout > 0) || !(o.duration >= 0) || !std::isfinite(o.duration))
            throw Error(LAG_ERR_ARG, "LAG_ERR_ARG: Controller: timeout > 0 and a finite "
                                     "duration >= 0, not " + std::to_string(o.timeout) + ", " +
                                     std::to_string(o.duration));
        c_.on_event([this](const Event &ev) {
            stopped_ |= ev.is("stop");
            if (user_event_) user_event_(ev);
        });
        if (o_.signals) {
            signal_flag() = 0;
            struct sigaction sa = {};
            sa.sa_handler = &Controller::on_signal;
            sigemptyset(&sa.sa_mask); /* no SA_RESTART: a wait returns at once */
            sigaction(SIGINT, &sa, &old_int_);
            sigaction(SIGTERM, &sa, &old_term_);
        }
    }
    ~Controller()
    {
        if (o_.signals) {
            sigaction(SIGINT, &old_int_, nullptr);
            sigaction(SIGTERM, &old_term_, nullptr);
        }
    }
    Controller(const Controller &) = delete;
    Controller &operator=(const Controller &) = delete;

    /* The scene (DESCRIBE until it comes, Client::wait_scene) within Options::timeout
     * wall s; std::nullopt when a signal ended the wait (end() "signal"); Error with
     * LAG_TIMEOUT when none came (end() "silence"), naming the plants heard instead.
     * Optional: next() returns states without it, each once its scene came (the scene
     * rule, lagsim_client.h). */
    std::optional<Scene> wait_scene()
    {
        Scene sc;
        for (double until = lag_client_now() + o_.timeout;;) {
            if (o_.signals && signal_flag()) return ended_scene("signal");
            double left = until - lag_client_now();
            if (left <= 0) {
                end_ = "silence";
                throw c_.no_scene(o_.timeout);
            }
            if (c_.try_wait_scene(left < 0.25 ? left : 0.25, sc)) return sc;
        }
    }
    /* The newest state not yet returned, or std::nullopt once the run has ended (end()).
     * A copy of a state already answered is answered by the library with the same
     * command, never returned: the law runs once per state. */
    std::optional<State> next()
    {
        if (!end_.empty()) return std::nullopt;
        if (o_.duration > 0 && states_ > 0 &&
            last_.sim_time - t_first_ >= o_.duration - 0.5 * period()) {
            end_ = "duration";
            return std::nullopt;
        }
        for (;;) {
            if (o_.signals && signal_flag()) return ended("signal");
            std::optional<State> st = c_.wait_state(0.05);
            if (st) {
                if (states_++ == 0) t_first_ = st->sim_time;
                last_ = *st;
                return st;
            }
            if (stopped_) return ended("stop");
            if (lag_client_now() - c_.heard() > o_.timeout) return ended("silence");
        }
    }
    /* Answers state st with efforts for the joints named; a non-finite effort is sent as
     * 0, never NaN (Client::send_command for the errors). */
    void send_command(const State &st, const std::vector<std::string> &names,
                      std::vector<double> effort)
    {
        for (double &e : effort) e = std::isfinite(e) ? e : 0.0;
        c_.send_command(st, names, effort);
    }

    /* why the run ended ("" while it runs): stop, silence, duration, signal */
    const std::string &end() const { return end_; }
    /* states returned by next() */
    long long states() const { return states_; }
    /* the scene of the state last returned (Client::latest_scene): its parameters */
    std::optional<Scene> scene() const { return c_.latest_scene(); }
    /* events from the daemon (after the Controller has looked for its stop) */
    void on_event(std::function<void(const Event &)> f) { user_event_ = std::move(f); }
    Client &client() { return c_; }
    const Options &options() const { return o_; }
    /* whether a host's directory named the plant's URL (options().url) */
    bool located() const { return located_; }

private:
    static volatile std::sig_atomic_t &signal_flag()
    {
        static volatile std::sig_atomic_t flag = 0;
        return flag;
    }
    static void on_signal(int sig) { signal_flag() = sig; }
    std::optional<State> ended(const char *why)
    {
        end_ = why;
        return std::nullopt;
    }
    std::optional<Scene> ended_scene(const char *why)
    {
        end_ = why;
        return std::nullopt;
    }
    double period() const
    {
        std::optional<Scene> sc = c_.latest_scene();
        double p = sc ? sc->control_period() : 0.0;
        return std::isfinite(p) ? p : 0.0;
    }

    static bool locate_into(const std::string &prefix, std::string &url);

    Options o_;
    bool located_;
    Client c_;
    std::function<void(const Event &)> user_event_;
    struct sigaction old_int_ = {}, old_term_ = {};
    std::string end_;
    bool stopped_ = false;
    double t_first_ = 0;
    long long states_ = 0;
    State last_;
};

/* The plants on the bus at url (lag_client_discover). */
inline std::vector<Plant> discover(const std::string &url = "", double wait_s = 1.0,
                                   double settle_s = 0.5)
{
    std::vector<Plant> p(LAG_CLIENT_MAX_PLANTS);
    int n = 0;
    char err[512] = "";
    lag_result rc = lag_client_discover(url.empty() ? nullptr : url.c_str(), wait_s, settle_s,
                                        p.data(), LAG_CLIENT_MAX_PLANTS, sizeof(Plant), &n, err,
                                        sizeof err);
    if (rc < 0) throw Error(rc, detail::describe(rc, err));
    p.resize(static_cast<size_t>(n));
    return p;
}

/* The only plant (of `model`, unless empty) on the bus: Error with LAG_TIMEOUT (none) or
 * LAG_ERR_AMBIGUOUS (several: the message names them). */
inline Plant pick_plant(const std::string &url = "", const std::string &model = "",
                        double wait_s = 1.0)
{
    Plant p;
    char err[1200] = "";
    lag_result rc = lag_client_pick_plant(url.empty() ? nullptr : url.c_str(),
                                          model.empty() ? nullptr : model.c_str(), wait_s, &p,
                                          sizeof p, err, sizeof err);
    if (rc != LAG_OK) throw Error(rc, detail::describe(rc, err));
    return p;
}

/* Where the plant on prefix runs when no URL was given (lag_client_locate): where is
 * LAG_CLIENT_LOCATE_HOST when a host's directory on LCM's default bus names another URL
 * (url), LAG_CLIENT_LOCATE_HERE for a plant of that bus, LAG_CLIENT_LOCATE_NONE when nothing
 * of it came within wait_s (url: that bus's state URL for both). Error for a prefix a plant
 * cannot have, LCM failing. */
struct Located {
    int where = LAG_CLIENT_LOCATE_NONE;
    std::string url;
    bool host() const { return where == LAG_CLIENT_LOCATE_HOST; }
};
inline Located locate(const std::string &prefix, double wait_s = LAG_CLIENT_LOCATE_WAIT_S)
{
    char url[LAG_CLIENT_URL_LEN] = "", err[256] = "";
    int where = lag_client_locate(prefix.c_str(), wait_s, url, sizeof url, err, sizeof err);
    if (where < 0) {
        lag_result rc = static_cast<lag_result>(where);
        throw Error(rc, detail::describe(rc, err));
    }
    Located l;
    l.where = where;
    l.url = url;
    return l;
}

inline bool Controller::locate_into(const std::string &prefix, std::string &url)
{
    Located l = locate(prefix);
    if (l.host()) url = l.url;
    return l.host();
}

} // namespace lagsim

#endif
