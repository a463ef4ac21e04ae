# The tiers: every ctest carries exactly one tier label, given here and nowhere else
# (docs/testing.md, "Tiers", says what each holds; structure_names fails on a ctest with
# no tier or with two, and structure_docs on a tier the table there lacks).
#
#   quick      waits on no wall clock: the core, scenes, the wire, replays, the bounded
#              decoders, made-up clocks, lockstep runs; `tests/run.sh` (the developer's loop)
#   wallclock  paces in real time: a control loop or a daemon that must be scheduled
#              every period (real-time runs, lagsimctl against a running plant, floods and
#              signals to a real daemon, the terminal's live line)
#   waits      waits on the wall clock with next to nothing to compute: a law that sleeps,
#              a silence, a deadline, a stalled peer, connections held open
#   browser    drives headless Chromium
#   octave     starts GNU Octave
#   root       network namespaces, nftables, sshd per namespace (skipped when not root)
#   package    installs the Debian package (dpkg: one at a time)
#   slow       long computations (10^8 ticks, 200-run sweeps); not in the sanitizer pass
#   bench      benchmarks' quick checks (no sanitizer build)
#   fuzz_run   bounded fuzzing (the sanitizer pass only)
#
# A tier comes from the first rule below that matches the test, by one of its labels
# (LABEL: the area says it all: a new core_* test is quick by nature) or by its name
# (NAME, for the areas that hold several natures). A test no rule matches gets no tier and
# fails structure_names: add its rule here, in the tier its nature says.
#
# Read at configure time (lagsim_apply_tiers, for add_test's tests) and by ctest
# (tests/common/cases.cmake's include files, for the cases a test program lists): so plain
# script commands only.
include_guard(GLOBAL)

set(LAGSIM_TIERS quick wallclock waits browser octave root package slow bench fuzz_run)

set(LAGSIM_TIER_RULES
  "slow      LABEL ^slow$"
  "fuzz_run  LABEL ^fuzz_run$"
  "bench     LABEL ^bench$"
  "package   LABEL ^package$"
  "quick     LABEL ^(core|effects|wire|result|structure|fuzz|accuracy)$"
  # the protocol's conformance traces, played against each language's controller
  "quick     NAME  ^protocol_"
  # what only waits, in any area (first: some of these names match the rules below)
  # (not Java's: a JVM starting and classes compiled for the slow law compute; run beside
  # the others and two busy processes, clients_readme_java_slower_law and
  # clients_cross_language_slower_law ran past their 90 s)
  "waits     NAME  ^clients_readme_(c|cpp|python|lua|go)_slow(er)?_law$"
  "waits     NAME  ^clients_(c|cpp|python|lua|java|go)_[a-z_]+_ends_on_(stop|silence)$"
  "waits     NAME  ^clients_(c|cpp|python|lua|java|go)_ends_on_signal$"
  # README's C, C++ and Python blocks under a daemon SIGKILLed: each waits out its 5 s of silence
  "waits     NAME  ^clients_readme_(c|cpp|python|go)_daemon_killed$"
  "waits     NAME  ^clients_(python|java)_dipc_late_controller$"
  "waits     NAME  ^view_attack_(slowloris|stalled)$"
  "waits     NAME  ^eval_lagsim_(eval_errors|sweep_stalled)$"
  "waits     NAME  ^eval_procs_(eval|sweep)_(stalled|gnuplot)$"
  "waits     NAME  ^eval_lagsim_sweep_unanswered$"
  # a controller on another prefix: a kept pair's wait for its first answer (--timeout 8)
  "waits     NAME  ^eval_lagsim_sweep_controller_exit$"
  # a kept pair's controller that starts after a wait of 12 s (sleep 12)
  "waits     NAME  ^eval_lagsim_sweep_slow_start$"
  "waits     NAME  ^eval_lagsim_eval_waits$"
  "waits     NAME  ^scene_shipped_wait$"
  "waits     NAME  ^log_term_waits$"
  "waits     NAME  ^ctl_discover$"
  # scene: every loader check
  "quick     LABEL ^scene$"
  # net: namespaces need root; the URL rule in each language, the receive filter over LCM
  "root      NAME  ^net_two_hosts_"
  "octave    NAME  ^net_plant_urls_octave$"
  "quick     NAME  ^net_(plant_urls|filter)_"
  # server: the loop, the pacer and the floors on made-up clocks or none; the plant's own
  # receive sockets against LCM's datagrams (as net_filter_: delivery, no pace); the
  # daemon's lockstep, fast and offline references; every other server_test case runs
  # lagsimd in real time (watchdog, floods, signals, plants that conflict, a host's plants)
  "quick     NAME  ^server_(loop|pace|rx)_"
  "quick     NAME  ^server_daemon_floors$"
  "quick     NAME  ^server_reference_(lockstep|fast|offline|manipulator)$"
  "wallclock NAME  ^server_"
  # log: the writer on a made-up clock; lockstep and fast runs logged, read, converted;
  # the terminal's live line and waits in real time
  "quick     NAME  ^log_(rt|outputs)_"
  "quick     NAME  ^log_(lqr|lqr_effects|gaps|readers|cli)$"
  "wallclock NAME  ^log_(flood|flood_applied)$"  # realtime runs flooded for 3 s of 5
  "quick     NAME  ^log_series_"
  "quick     NAME  ^log_old_version_"
  "wallclock NAME  ^log_term_"
  # view: the log tools; Chromium; attacks that take time or namespaces
  "wallclock NAME  ^view_log2csv_load$"  # a real-time run recorded, then loaded
  "quick     NAME  ^view_log2csv_"
  "quick     NAME  ^view_stop_"
  "wallclock NAME  ^view_attack_(slowloris|stalled)$"
  "root      NAME  ^view_attack_lan$"
  "browser   NAME  ^view_(browser|hostile|stick_flight|cartpole|reference|charts|history|models|attack_forged|attack_host)$"
  # eval: unit tests; lagsim-eval and lagsim-sweep in lockstep; --timeout, a stalled
  # controller; packet loss and ssh hosts in namespaces
  "quick     NAME  ^eval_(metrics|reference|sweep_csv)_"
  "quick     NAME  ^eval_procs_(eval|sweep)_(sigint|sigterm|sigkill|groupkill)$"
  "quick     NAME  ^eval_lagsim_eval_(metrics|require|scene|owned|outputs|bus|docs_python|notes|stderr)$"
  "quick     NAME  ^eval_lagsim_sweep_(same|slurm|merge|merge_rows|merge_foreign|shard|kept|kept_python|vary|scene_c|scene_python|notes|interrupt|tmpdir)$"
  "wallclock NAME  ^eval_lagsim_(eval_errors|sweep_stalled)$"
  # the progress line on a terminal: drawn against the wall clock
  "wallclock NAME  ^eval_lagsim_sweep_progress$"
  "root      NAME  ^eval_lagsim_sweep_(loss|ssh|scene_loss)$"
  # clients, ctl, install
  "quick     NAME  ^clients_octave_matlab_syntax$"
  "octave    NAME  ^clients_(octave_|readme_octave$)"
  "octave    NAME  ^clients_cross_language_generation$"  # C, Python, Lua, Java and Octave
  "wallclock NAME  _(realtime|ends_on_stop|ends_on_silence|late_controller|slow_law|slower_law)$"
  "wallclock NAME  ^clients_(readme_recipes|walkthrough|scene_params)$"
  "wallclock NAME  ^ctl_"
  "quick     NAME  ^install_"
  "quick     NAME  ^clients_(lqr|status_fields|hostile_messages|library|generation|small_stack|locate|first_burst|not_built)$"
  "quick     NAME  ^clients_[a-z_]+_(usage_.*|help)$"
  "quick     NAME  ^clients_(python|lua)_(lcm|types)$"
  "quick     NAME  ^clients_java_release$"
  "quick     NAME  ^clients_(go_dipc_gain|go_vet|go_cgo_rebuild|binding_lookup|binding_constants)$"
  "quick     NAME  _(lockstep|hostile|push|reference_lost)$"
  # a lab host's plants in lockstep, found by their prefix through its directory
  "quick     NAME  ^clients_(c|cpp|python|lua|go|java)_host_prefix$"
  "quick     NAME  ^clients_cross_language_(dipc|manipulator)$"
  "quick     NAME  ^clients_readme_(c|cpp|cpplcm|python|lua|java|go)$"
  # the client library: its version, its ABI, its C++ header, the README's C and C++ blocks
  # against an install and by the other C++ compiler (lockstep runs, compilations)
  "quick     NAME  ^clients_(versions|abi|abi_mutations|cpp_header|lcm_cpp_forged)$"
  "quick     NAME  ^clients_model_[a-z_]+$"  # the client library's M and h vs T and U
  "quick     NAME  ^clients_readme_(c|cpp)_installed$"
  "quick     NAME  ^clients_readme_go_static$"
  "quick     NAME  ^clients_(readme_cpp|manipulator_ct)_other_compiler$"
)

# How a tier's tests run inside a pass: tests/run.sh runs one ctest per pass with
# -j (100 x cores), and each test takes its tier's share of that (its PROCESSORS): the
# hundredths of a core its tests use on average while they run, as measured by
# tests/common/cpu_profile.py, rounded up; more for the tiers that start many threads or
# processes at once (Octave's JVM, Chromium, dpkg); and never less than 25, so that at
# most 4 tests a core run at once (docs/testing.md, "Time", has the measures and what a
# smaller share did to a real-time plant). The cost (COST) is the order ctest starts
# them in: an explicit cost, which ctest's timings of earlier runs do not change; the
# long kinds first, so that none of them is left running alone at the end. The fuzz
# targets start first, one at a time (a resource lock, tests/fuzz/fuzz.cmake), with half
# a core: a fuzzer takes the CPU the others leave for a fixed time, so it runs beside
# them through the pass instead of after them, two at a time, with nothing else.
#   tier       share cost
set(LAGSIM_TIER_RUN
  "quick         40    10"
  "wallclock     25    30"
  "waits         25    40"
  "browser       50    20"
  "octave        50    30"
  "root          25    40"
  "package       60    60"
  "slow          30    30"
  "bench        100    10"
  "fuzz_run      50    70"
)

# lagsim_tier_run(TIER OUT): OUT = the properties a test of TIER runs with
# (PROCESSORS <share> COST <cost>), or "" for a tier the table lacks.
function(lagsim_tier_run tier out)
  set(props "")
  foreach(row IN LISTS LAGSIM_TIER_RUN)
    string(REGEX MATCH "^([a-z_]+) +([0-9]+) +([0-9]+)$" m "${row}")
    if(CMAKE_MATCH_1 STREQUAL "${tier}")
      set(props PROCESSORS ${CMAKE_MATCH_2} COST ${CMAKE_MATCH_3})
    endif()
  endforeach()
  set(${out} "${props}" PARENT_SCOPE)
endfunction()

# lagsim_tier_of(NAME "LABELS" OUT): OUT = the tier of the first rule that matches, or "".
function(lagsim_tier_of name labels out)
  foreach(rule IN LISTS LAGSIM_TIER_RULES)
    string(REGEX MATCH "^([a-z_]+) +(LABEL|NAME) +(.+)$" m "${rule}")
    set(tier ${CMAKE_MATCH_1})
    set(kind ${CMAKE_MATCH_2})
    set(rx "${CMAKE_MATCH_3}")
    if(kind STREQUAL "NAME")
      if(name MATCHES "${rx}")
        set(${out} ${tier} PARENT_SCOPE)
        return()
      endif()
    else()
      foreach(l IN LISTS labels)
        if(l MATCHES "${rx}")
          set(${out} ${tier} PARENT_SCOPE)
          return()
        endif()
      endforeach()
    endif()
  endforeach()
  set(${out} "" PARENT_SCOPE)
endfunction()

# Gives every test of this directory made by add_test its tier (the cases a program lists
# get theirs when ctest reads them: cases.cmake).
function(lagsim_apply_tiers)
  get_property(tests DIRECTORY PROPERTY TESTS)
  foreach(t IN LISTS tests)
    get_test_property(${t} LABELS labels)
    if(NOT labels)
      set(labels "")
    endif()
    lagsim_tier_of(${t} "${labels}" tier)
    if(tier)
      list(APPEND labels ${tier})
      list(REMOVE_DUPLICATES labels)
      lagsim_tier_run(${tier} run)
      set_tests_properties(${t} PROPERTIES LABELS "${labels}" ${run})
    endif()
  endforeach()
endfunction()
