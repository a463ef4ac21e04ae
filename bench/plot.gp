# Work-precision plots of lagsim_bench's CSV (run by bench/run.sh):
#   gnuplot -e "outdir='docs'" bench/plot.gp
# docs/bench_wp_<scene>.png: max position error over the horizon vs CPU seconds per
# simulated second, log-log, one curve per method (lagsim solid, peers dashed).
# docs/bench_energy_long.png: energy error vs time, chaotic DIPC, 100 s.
if (!exists("outdir")) outdir = "docs"
csv = outdir . "/bench_wp.csv"
set datafile separator ","
set datafile missing "NaN"
set terminal pngcairo size 1000,700 enhanced font "DejaVu Sans,11"
set logscale xy
set format x "10^{%L}"
set format y "10^{%L}"
set grid xtics ytics mxtics mytics lc rgb "#dddddd"
set key outside right top spacing 1.1
set xlabel "CPU time per simulated second (s/s = fraction of one core at real time)"
set ylabel "max position error over the horizon (m or rad)"

scenes = "dipc_swing manip_torque stick_fall dipc_chaos"
titles = "'DIPC hanging, swinging, 10 s' 'manipulator, smooth torque, 5 s' 'stick falling from rest, 1 s' 'DIPC near upright (chaotic), 2 s'"
curves = "lagsim:euler lagsim:semi-implicit-euler lagsim:implicit-midpoint lagsim:rk4 lagsim:gauss4 lagsim:dopri5 lagsim:dopri5-continuous mujoco:Euler mujoco:RK4 mujoco:implicit sundials:ARKODE-DP5 sundials:ARKODE-RK4 sundials:CVODE-Adams sundials:CVODE-BDF"
# points of one curve: CPU per sim s ($10), error ($6); failed runs (status != 0) left out
sel(s, c) = sprintf("< awk -F, 'NR > 1 && $1 == \"%s\" && $2\":\"$3 == \"%s\" && $12 == 0 {print $10 \",\" $6}' %s", s, c, csv)
lab(c) = system(sprintf("echo '%s' | tr ':' ' '", c))

# line types: lagsim methods solid with filled points, peers dashed with open points
colors = "#1f77b4 #ff7f0e #2ca02c #d62728 #9467bd #8c564b #000000 #e377c2 #7f7f7f #bcbd22 #17becf #393b79 #637939 #843c39"
do for [i = 1:words(curves)] {
    eval sprintf("set linetype %d lc rgb '%s' lw 2 pt %d ps 0.9 dt %d", i, word(colors, i), \
                 i <= 7 ? 7 : 6, i <= 7 ? 1 : 2)
}

do for [k = 1:words(scenes)] {
    s = word(scenes, k)
    set output sprintf("%s/bench_wp_%s.png", outdir, s)
    set title sprintf("Work-precision: %s", word(titles, k))
    plot for [i = 1:words(curves)] sel(s, word(curves, i)) using 1:2 \
         with linespoints lt i title lab(word(curves, i))
}

# energy error vs time
unset logscale x
set format x "%g"
set xlabel "time (s)"
set ylabel "abs(E(t) - E(0)) (J)"
set title "Energy error, DIPC near upright (chaotic), 100 s, unforced"
set output sprintf("%s/bench_energy_long.png", outdir)
ecsv = outdir . "/bench_energy_long.csv"
ncol = int(system(sprintf("head -1 %s | awk -F, '{print NF}'", ecsv)))
plot for [i = 2:ncol] ecsv using 1:(column(i) > 0 ? column(i) : NaN) with lines \
     lt (i - 1) title columnhead(i)
