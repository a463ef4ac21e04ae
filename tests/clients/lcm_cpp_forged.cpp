/*
 * What stock lcm-gen --cpp types (used with lcm/lcm-cpp.hpp, whose typed subscriptions
 * deliver every message whose decode() does not return < 0) accept that lagsim's client
 * library refuses: the forged messages docs/clients.md shows, "In C++ with lcm-gen's
 * types". Each is built from a state the generated encoder wrote, then changed as a
 * forger would; the generated decoder must take it (the claim in the docs, which this
 * keeps true for the LCM in use) and lag_client_feed must drop and count it.
 *
 *   - a name whose final NUL is another byte: "theta0X" (length 7) reads as "theta0"
 *   - bytes after the end of the message: ignored
 *   - a NaN position: taken as it is
 *
 * usage: test_lcm_cpp_forged   (exit 0: every claim holds; prints each)
 */
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <lagsim/joint_state_t.hpp>

#include "lagsim_client.h"

static int failures = 0;

static void check(bool ok, const std::string &what)
{
    std::printf("%s: %s\n", ok ? "ok  " : "FAIL", what.c_str());
    failures += !ok;
}

static std::vector<unsigned char> encode(const lagsim::joint_state_t &m)
{
    std::vector<unsigned char> b(static_cast<size_t>(m.getEncodedSize()));
    m.encode(b.data(), 0, static_cast<int>(b.size()));
    return b;
}

/* The stock decoder's verdict, and the client library's (dropped: counted). */
static void judge(const char *what, const std::vector<unsigned char> &b, lag_client *c,
                  bool (*as_read)(const lagsim::joint_state_t &))
{
    lagsim::joint_state_t m;
    int n = m.decode(b.data(), 0, static_cast<int>(b.size()));
    check(n >= 0 && as_read(m), std::string("lcm-gen --cpp takes ") + what);
    lag_client_counters before, after;
    lag_client_get_counters(c, &before, sizeof before);
    lag_client_feed(c, "FORGED_STATE", b.data(), b.size());
    lag_client_get_counters(c, &after, sizeof after);
    check(after.dropped == before.dropped + 1 && after.states == before.states,
          std::string("the client library drops ") + what);
}

int main()
{
    char err[256];
    lag_client *c = lag_client_create("memq://", "FORGED", err, sizeof err);
    if (!c) {
        std::printf("FAIL: %s\n", err);
        return 1;
    }
    lagsim::joint_state_t m;
    m.utime = 1;
    m.sim_time = 0.5;
    m.step = 50;
    m.num_joints = 1;
    m.name = {"theta0"};
    m.position = {0.1};
    m.velocity = {0.0};
    m.effort = {0.0};
    m.generation = 1;
    std::vector<unsigned char> ok = encode(m);

    /* the name's final NUL replaced: 8 + 8 + 8 + 8 + 2 bytes, then its length (4), then
     * "theta0" and the NUL at offset 34 + 4 + 6 */
    std::vector<unsigned char> b = ok;
    const size_t nul = 8 + 8 + 8 + 8 + 2 + 4 + 6;
    check(b[nul] == 0 && std::memcmp(&b[nul - 6], "theta0", 6) == 0, "the layout as expected");
    b[nul] = 'X';
    judge("a name \"theta0X\" without its NUL, read as \"theta0\"", b, c,
          [](const lagsim::joint_state_t &s) { return s.name[0] == "theta0"; });

    b = ok;
    b.insert(b.end(), {0xde, 0xad, 0xbe});
    judge("3 bytes after the message, ignored", b, c,
          [](const lagsim::joint_state_t &s) { return s.position[0] == 0.1; });

    m.position = {std::numeric_limits<double>::quiet_NaN()};
    judge("a NaN position, as it is", encode(m), c,
          [](const lagsim::joint_state_t &s) { return std::isnan(s.position[0]); });

    lag_client_destroy(c);
    std::printf("%d failure(s)\n", failures);
    return failures ? 1 : 0;
}
