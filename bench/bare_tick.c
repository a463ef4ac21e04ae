/* One model, bare (no effects), rk4 at dt = 1 ms, 20000 ticks: a fixed amount of work
 * whose instruction count (valgrind --tool=callgrind) compares one core with another.
 * Uses only the API of the first core (commit e5ed52d), so bench/bare_cost_history.sh
 * can build it against any later one. usage: bare_tick stick|manipulator|dipc */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include "lagsim/lagsim.h"

int main(int argc, char **argv)
{
    int kind = argc > 1 ? lag_model_kind_from_name(argv[1]) : LAG_MODEL_DIPC;
    if (kind < 0) {
        fprintf(stderr, "usage: bare_tick stick|manipulator|dipc\n");
        return 2;
    }
    lag_sim_def d = lag_default_sim_def((lag_model_kind)kind);
    d.q0[1] = (kind == LAG_MODEL_STICK) ? 1.2 : 0.5;
    if (kind == LAG_MODEL_DIPC) { d.q0[1] = M_PI + 0.5; d.q0[2] = M_PI - 0.3; }
    if (kind == LAG_MODEL_MANIPULATOR) d.q0[0] = 0.3;
    lag_sim s;
    char err[256];
    if (lag_sim_init(&s, &d, err, sizeof err) != LAG_OK) {
        fprintf(stderr, "%s\n", err);
        return 1;
    }
    lag_result r = lag_sim_advance(&s, 20000, false);
    printf("%s: %s, q0 = %.17g\n", argv[1] ? argv[1] : "dipc", lag_result_string(r), s.q[0]);
    return r == LAG_OK ? 0 : 1;
}
