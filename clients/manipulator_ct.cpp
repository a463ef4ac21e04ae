/*
 * manipulator_ct: the rotary/prismatic manipulator tracking the scene's reference with
 * computed torque, in C++17 over the client library alone (lagsim_client.hpp):
 *
 *   tau = M(q) (r'' + Kd (r' - qd) + Kp (r - q)) + C(q, qd) qd + g(q),  Kp = wn^2, Kd = 2 wn
 *
 * r, r', r'' from <PREFIX>_REFERENCE (published just before each state with its sim_time:
 * the feedforward is exact, no difference of r'); M(q) and the bias h = C(q, qd) qd + g(q)
 * from the client library (lagsim::Scene::mass, bias: the core's closed forms with the
 * scene's parameters, docs/clients.md), nothing of the model written here. With the exact
 * model the error obeys e'' + Kd e' + Kp e = 0 (critically damped), up to the zero-order
 * hold of the effort over a control period.
 *
 * What it links, and why: only liblagsim_client (pkg-config lagsim-client), as a
 * controller outside lagsim's tree does. tau = M v + h is summed in the order of the C
 * manipulator_pd (which calls the core), so that the two answer every state with the same
 * bits (clients_cross_language_manipulator).
 *
 * The run, its options and its summary line are those of the C examples
 * (docs/clients.md): --prefix (default: the only manipulator on the bus, else
 * MANIPULATOR), --url, --duration, --timeout, --trace, -q; it ends on the daemon's stop
 * event, after --timeout wall seconds of silence, after --duration, or on SIGINT/SIGTERM.
 *
 *   c++ -std=c++17 manipulator_ct.cpp $(pkg-config --cflags --libs lagsim-client)
 */
#include <getopt.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <string>

#include "lagsim_client.hpp"

namespace {

struct Options {
    std::string prefix, url, trace;
    double duration = 0, timeout = 5, wn = 10, settle = 2;
    bool quiet = false;
};

using Vec2 = std::array<double, 2>;

/* tau = M(q) v + h(q, qd), M and h = C(q, qd) qd + g(q) from the client library. */
Vec2 computed_torque(const lagsim::Scene &sc, const Vec2 &q, const Vec2 &qd, const Vec2 &v)
{
    double M[4], h[2];
    sc.mass(2, q.data(), M);
    sc.bias(2, q.data(), qd.data(), h);
    return {M[0] * v[0] + M[1] * v[1] + h[0], M[2] * v[0] + M[3] * v[1] + h[1]};
}

/* The tracking error over the run: its peaks, and after --settle its RMS. */
struct Tracking {
    long long states = 0, settled = 0, stale = 0;
    double t_first = NAN, t_last = NAN, t_report = -INFINITY;
    Vec2 emax{}, esq{}, emax_all{};
    void add(double t, const Vec2 &e, double settle)
    {
        if (states++ == 0) t_first = t;
        t_last = t;
        bool in = t - t_first >= settle;
        settled += in;
        for (int k = 0; k < 2; k++) {
            emax_all[k] = std::max(emax_all[k], std::fabs(e[k]));
            if (in) emax[k] = std::max(emax[k], std::fabs(e[k])), esq[k] += e[k] * e[k];
        }
    }
};

int usage(std::ostream &o, int status)
{
    o << "usage: manipulator_ct [options]\n"
         "Tracks the scene's reference (<PREFIX>_REFERENCE: r, r', r'') on a running lagsimd\n"
         "manipulator with computed torque, M(q) and C(q, qd) qd + g(q) from the client\n"
         "library (C++ over the client library alone).\n"
         "  --prefix P           channel prefix (default: the only manipulator on the bus;\n"
         "                       none yet: MANIPULATOR)\n"
         "  --url URL            LCM URL (default: the URL a host's directory on LCM's\n"
         "                       default bus names for --prefix, else LCM's default;\n"
         "                       honours LCM_DEFAULT_URL)\n"
         "  --duration S         end after S s of sim time from the first state (default 0:\n"
         "                       until the daemon stops)\n"
         "  --timeout S          wall s without a scene, or without any message from the\n"
         "                       daemon, before ending (default 5)\n"
         "  --trace FILE         write each answered state and the efforts sent to FILE\n"
         "  --wn W               bandwidth, rad/s: Kp = W^2, Kd = 2 W (default 10)\n"
         "  --settle S           error statistics skip the first S s (default 2)\n"
         "  -q, --quiet          summary only\n"
         "  -h, --help           this text\n"
         "A run ends on the daemon's stop event, after --timeout s of silence, after\n"
         "--duration, or on SIGINT/SIGTERM.\n"
         "Exit status: 0 done, 1 no scene, another model or a client error, 2 bad usage.\n";
    return status;
}

/* A finite number (> 0 when positive), the whole of `s`; else exits 2 naming the option. */
double number(const char *opt, const char *s, bool positive)
{
    char *end = nullptr;
    double x = std::strtod(s, &end);
    if (end == s || *end || !std::isfinite(x) || (positive ? !(x > 0) : !(x >= 0))) {
        std::cerr << "manipulator_ct: --" << opt << ": '" << s << "' is not a finite number "
                  << (positive ? "> 0" : ">= 0") << "\n";
        std::exit(2);
    }
    return x;
}

/* -1 to go on, else the exit status. */
int parse(int argc, char **argv, Options &o)
{
    static const option longs[] = {
        {"prefix", required_argument, nullptr, 'p'}, {"url", required_argument, nullptr, 'u'},
        {"duration", required_argument, nullptr, 'd'}, {"timeout", required_argument, nullptr, 't'},
        {"trace", required_argument, nullptr, 'T'}, {"wn", required_argument, nullptr, 'w'},
        {"settle", required_argument, nullptr, 's'}, {"quiet", no_argument, nullptr, 'q'},
        {"help", no_argument, nullptr, 'h'}, {nullptr, 0, nullptr, 0}};
    opterr = 0;
    for (int c; (c = getopt_long(argc, argv, ":qh", longs, nullptr)) != -1;) {
        switch (c) {
        case 'p': o.prefix = optarg; break;
        case 'u': o.url = optarg; break;
        case 'T': o.trace = optarg; break;
        case 'd': o.duration = number("duration", optarg, false); break;
        case 't': o.timeout = number("timeout", optarg, true); break;
        case 'w': o.wn = number("wn", optarg, true); break;
        case 's': o.settle = number("settle", optarg, false); break;
        case 'q': o.quiet = true; break;
        case 'h': return usage(std::cout, 0);
        default:
            std::cerr << "manipulator_ct: " << (c == ':' ? "option needs a value: " : "unknown option: ")
                      << argv[optind - 1] << " (--help lists the options)\n";
            return 2;
        }
    }
    if (optind < argc) {
        std::cerr << "manipulator_ct: unexpected argument '" << argv[optind] << "'\n";
        return 2;
    }
    return -1;
}

/* Without --prefix: the only manipulator on the bus, else MANIPULATOR (waited for). */
int choose_prefix(Options &o)
{
    if (!o.prefix.empty()) return -1;
    try {
        lagsim::Plant p = lagsim::pick_plant(o.url, "manipulator", 1.0);
        o.prefix = p.prefix;
        if (o.url.empty()) o.url = p.url; /* a host's plant: the URL its directory names */
        std::cout << "manipulator_ct: the only manipulator plant on the bus: prefix " << o.prefix << "\n";
    } catch (const lagsim::Error &e) {
        if (e.code() != LAG_TIMEOUT) {
            std::cerr << "manipulator_ct: " << e.what() << "\n";
            return e.code() == LAG_ERR_AMBIGUOUS ? 2 : 1;
        }
        o.prefix = "MANIPULATOR";
    }
    return -1;
}

/* The scene, within --timeout (lagsim::Controller::wait_scene: a signal ends the wait;
 * none in time: the plants on the bus instead, for a misspelt --prefix). */
std::optional<lagsim::Scene> scene_of(lagsim::Controller &ctl, const Options &o)
{
    std::cout << "manipulator_ct: waiting for the scene description on " << o.prefix << "_SCENE"
              << std::endl; /* subscribed: the harnesses start the daemon on this line */
    try {
        return ctl.wait_scene(); /* std::nullopt: a signal */
    } catch (const lagsim::Error &e) {
        if (e.code() != LAG_TIMEOUT) throw;
        std::cerr << "manipulator_ct: " << e.what() << "\n"; /* the plants heard instead */
        return std::nullopt;
    }
}

/* Runs the law on every state until the run ends (lagsim::Controller: the daemon's stop,
 * --timeout s of silence, --duration, SIGINT/SIGTERM). */
void control(lagsim::Controller &ctl, lagsim::Scene &sc, const Options &o, Tracking &tr,
             std::ofstream &trace)
{
    const double kp = o.wn * o.wn, kd = 2.0 * o.wn;
    const std::vector<std::string> jn = {"q1", "q2"};
    Vec2 hold{};
    while (std::optional<lagsim::State> st = ctl.next()) {
        if (st->generation != sc.generation()) /* a reset, a SET: its scene came with it */
            sc = *ctl.scene();
        const int i1 = st->joint(jn[0]), i2 = st->joint(jn[1]);
        if (i1 < 0 || i2 < 0) continue;
        const Vec2 q = {st->position[i1], st->position[i2]}, qd = {st->velocity[i1], st->velocity[i2]};
        if (tr.states == 0) hold = q;
        /* r, r', r'' of each joint (a joint without a reference holds its first position) */
        std::optional<lagsim::Reference> ref = ctl.client().reference_of(*st); /* its own */
        if (!ref && (ref = ctl.client().latest_reference())) tr.stale++; /* lost: the last kept */
        Vec2 r = hold, rd{}, rdd{};
        for (int k = 0; k < 2; k++)
            if (int j = ref ? ref->joint(jn[k]) : -1; j >= 0)
                r[k] = ref->r[j], rd[k] = ref->rdot[j], rdd[k] = ref->rddot[j];
        Vec2 v;
        for (int k = 0; k < 2; k++) v[k] = rdd[k] + kp * (r[k] - q[k]) + kd * (rd[k] - qd[k]);
        Vec2 tau = computed_torque(sc, q, qd, v);
        for (double &t : tau) t = std::isfinite(t) ? t : 0.0; /* never a NaN on the bus */
        ctl.send_command(*st, jn, {tau[0], tau[1]});
        if (trace.is_open()) {
            char buf[64];
            std::snprintf(buf, sizeof buf, "%.17g", st->sim_time);
            trace << buf;
            for (int i = 0; i < st->num_joints; i++)
                std::snprintf(buf, sizeof buf, " %.17g", st->position[i]), trace << buf;
            for (int i = 0; i < st->num_joints; i++)
                std::snprintf(buf, sizeof buf, " %.17g", st->velocity[i]), trace << buf;
            for (double t : tau) std::snprintf(buf, sizeof buf, " %.17g", t), trace << buf;
            trace << '\n';
        }
        tr.add(st->sim_time, {r[0] - q[0], r[1] - q[1]}, o.settle);
        if (!o.quiet && st->sim_time - tr.t_report >= 1.0) {
            tr.t_report = st->sim_time;
            std::printf("t=%8.3f  q1=%+.5f (e %+.2e)  q2=%+.5f (e %+.2e)  tau=%+.3f %+.3f\n",
                        st->sim_time, q[0], r[0] - q[0], q[1], r[1] - q[1], tau[0], tau[1]);
            std::fflush(stdout);
        }
    }
}

/* The summary line (the C examples' keys); returns the exit status, 0. */
int summary(lagsim::Controller &ctl, const Tracking &tr, const Options &o)
{
    lag_client_counters n = ctl.client().counters();
    Vec2 rms;
    for (int k = 0; k < 2; k++) rms[k] = tr.settled ? std::sqrt(tr.esq[k] / tr.settled) : NAN;
    std::printf("manipulator_ct: summary end=%s states=%lld t_first=%.6f t_last=%.6f settle=%g "
                "max_abs_e1=%.6g max_abs_e2=%.6g rms_e1=%.6g rms_e2=%.6g max_abs_e1_all=%.6g "
                "max_abs_e2_all=%.6g references_stale=%lld dropped=%lld repeats=%lld\n",
                ctl.end().c_str(), tr.states, tr.t_first, tr.t_last, o.settle, tr.emax[0],
                tr.emax[1], rms[0], rms[1], tr.emax_all[0], tr.emax_all[1], tr.stale,
                static_cast<long long>(n.dropped), static_cast<long long>(n.repeats));
    std::fflush(stdout);
    return 0;
}

} // namespace

int main(int argc, char **argv)
{
    Options o;
    if (int rc = parse(argc, argv, o); rc >= 0) return rc;
    if (int rc = choose_prefix(o); rc >= 0) return rc;
    std::ofstream trace;
    if (!o.trace.empty()) {
        trace.open(o.trace);
        if (!trace) {
            std::cerr << "manipulator_ct: --trace " << o.trace << ": cannot write\n";
            return 1;
        }
    }
    try {
        lagsim::Controller ctl(o.prefix, {o.url, o.timeout, o.duration, true, true});
        if (ctl.located())
            std::cout << "manipulator_ct: prefix " << o.prefix << " runs on " << ctl.options().url
                      << " (the host's directory)\n";
        Tracking tr;
        std::optional<lagsim::Scene> sc = scene_of(ctl, o);
        if (!sc) return ctl.end() == "signal" ? summary(ctl, tr, o) : 1;
        if (sc->model() != "manipulator" || !sc->actuated(sc->joint("q1")) ||
            !sc->actuated(sc->joint("q2"))) {
            std::cerr << "manipulator_ct: prefix " << o.prefix << " runs " << sc->model()
                      << ", not a manipulator with q1 and q2 actuated\n";
            return 1;
        }
        std::cout << "manipulator_ct: scene on " << o.prefix << "_*: mode " << sc->mode()
                  << ", control period " << sc->control_period() << " s; Kp " << o.wn * o.wn
                  << ", Kd " << 2 * o.wn << std::endl;
        control(ctl, *sc, o, tr, trace);
        return summary(ctl, tr, o);
    } catch (const lagsim::Error &e) {
        std::cerr << "manipulator_ct: " << e.what() << "\n";
        return 1;
    }
}
