/*
 * The conformance controller in C++, over lagsim_client.hpp: the conformance law, for
 * tests/protocol/play.py, as conformance.c writes it over the C library.
 *
 *   conformance_cpp --prefix P --url URL [--timeout S]
 *
 * For each state the library returns: u = -(kp q + kd qd) on each actuated joint of the
 * scene of that state's generation (latest_scene(); kp, kd: its parameters of those
 * names), one line "conformance: law generation=G sim_time=T" on stdout before the
 * command goes. It ends on the daemon's stop event (exit 0), or when no state came for
 * --timeout wall seconds (default 60; exit 0); no scene within --timeout: exit 1
 * (docs/protocol.md, "Checking a binding of your own").
 */
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include "lagsim_client.hpp"

int main(int argc, char **argv)
{
    std::string prefix = "CONFORMANCE", url;
    double timeout = 60.0;
    for (int i = 1; i < argc; i++) {
        if (i + 1 < argc && !std::strcmp(argv[i], "--prefix")) prefix = argv[++i];
        else if (i + 1 < argc && !std::strcmp(argv[i], "--url")) url = argv[++i];
        else if (i + 1 < argc && !std::strcmp(argv[i], "--timeout")) timeout = std::atof(argv[++i]);
        else {
            std::fprintf(stderr, "usage: conformance_cpp --prefix P --url URL [--timeout S]\n");
            return 2;
        }
    }
    try {
        if (url.empty()) { /* where a host's directory on the default bus says it runs */
            lagsim::Located l = lagsim::locate(prefix);
            if (l.host()) url = l.url;
        }
        lagsim::Client c(prefix, url);
        bool stopped = false;
        c.on_event([&](const lagsim::Event &ev) { stopped |= ev.is("stop"); });
        c.wait_scene(timeout);
        int laws = 0;
        for (double heard = lagsim::now(); !stopped && lagsim::now() - heard < timeout;) {
            std::optional<lagsim::State> st = c.wait_state(0.1);
            if (!st) continue;
            heard = lagsim::now();
            lagsim::Scene sc = *c.latest_scene(); /* the scene of this state's generation */
            const double kp = sc.find_param("kp").value_or(NAN), kd = sc.find_param("kd").value_or(NAN);
            std::vector<std::string> names;
            std::vector<double> u;
            bool whole = true;
            for (int j = 0; j < static_cast<int>(sc.joints().size()); j++) {
                if (!sc.actuated(j)) continue;
                int i = st->joint(sc.joints()[static_cast<size_t>(j)]);
                if (i < 0) whole = false;
                else {
                    names.push_back(sc.joints()[static_cast<size_t>(j)]);
                    u.push_back(-(kp * st->position[i] + kd * st->velocity[i]));
                }
            }
            if (!whole) continue;
            laws++;
            std::printf("conformance: law generation=%lld sim_time=%.17g\n",
                        static_cast<long long>(st->generation), st->sim_time);
            std::fflush(stdout);
            try {
                c.send_command(*st, names, u);
            } catch (const lagsim::Error &) { /* a NaN law (no kp): not sent, as in C */
            }
        }
        lag_client_counters k = c.counters();
        std::printf("conformance_cpp: summary end=%s laws=%d held=%lld describes=%lld "
                    "dropped=%lld repeats=%lld\n",
                    stopped ? "stop" : "silence", laws, static_cast<long long>(k.held),
                    static_cast<long long>(k.describes), static_cast<long long>(k.dropped),
                    static_cast<long long>(k.repeats));
        return 0;
    } catch (const lagsim::Error &e) {
        std::fprintf(stderr, "conformance_cpp: %s\n", e.what());
        return 1;
    }
}
