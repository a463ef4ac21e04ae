# Work-precision benchmark, quick check: short horizons, one coarse point per
# method. Fails if the reference's two methods (dopri5 rtol 1e-13, gauss4 at period/200)
# disagree by more than 1e-10, if at dt = 5e-3 a higher-order method is not more accurate
# than a lower-order one on every scene, if dopri5's error does not fall with its
# tolerance, or if our rk4 / semi-implicit Euler differ from MuJoCo's RK4 / Euler and
# ARKODE's RK4 (when built) by more than 1e-9 or 1 % of the integration error.
if(LAGSIM_BENCH)
  add_test(NAME bench_quick COMMAND lagsim_bench --quick)
  set_tests_properties(bench_quick PROPERTIES TIMEOUT 120 LABELS bench)
  # The cost-of-effects table has a row for every effect of the core's table: the
  # program fails by name on an effect it has no settings for (one repetition here)
  add_test(NAME bench_effects_cost_rows COMMAND effects_cost 1)
  set_tests_properties(bench_effects_cost_rows PROPERTIES TIMEOUT 300 LABELS bench
                       PASS_REGULAR_EXPRESSION "\\| spring \\|")
endif()
