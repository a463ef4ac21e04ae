# The stick thrown up spinning from its floor (docs/effects.md): heights of its ends and
# of its centre, and its energy, against sim time, with the floor's events.
#   build/bin/lagsimd --config config/stick.yaml --offline --duration 3 \
#       --set initial.qd=[0.4,12] --set effects.floor.restitution=0.5 --set publish_hz=1000 \
#       --csv build/flight.csv 2> build/flight_events.txt
#   gnuplot -e "dir='build'" docs/flight.gp          # writes docs/flight.png
# The CSV's columns: t,x,phi,h,x_dot,phi_dot,h_dot,energy (h: the lower end's height);
# the stick is config/stick.yaml's (l = 1 m).
if (!exists("dir")) dir = "build"
if (!exists("out")) out = "docs/flight.png"
csv = dir . "/flight.csv"
ev = dir . "/flight_events.txt"
l = 1.0
set datafile separator ","
set terminal pngcairo size 1000,760 enhanced font "DejaVu Sans,11"
set output out
set multiplot layout 2,1
set grid lc rgb "#dddddd"
set key top right
set lmargin 10
set ylabel "height above the floor (m)"
set title "stick thrown up spinning (phi_0 = 1.2 rad, phi dot_0 = 12 rad/s, x dot_0 = 0.4 m/s), floor restitution 0.5, rk4 dt 1 ms"
# events: "lagsimd: event KIND at t = T s, joint J, value V" (lagsimd prints the first 20;
# the last one here, the free end's rest, lying flat, is the 21st)
evsel(k) = sprintf("< awk '/event %s at/ {print $7 \",0\"}' %s", k, ev)
plot csv every ::1 using 1:($4 + l * abs(sin($3))) with lines lw 1.5 lc rgb "#9467bd" title "upper end", \
     csv every ::1 using 1:($4 + 0.5 * l * abs(sin($3))) with lines lw 2 lc rgb "#1f77b4" title "centre of mass", \
     csv every ::1 using 1:4 with lines lw 2 lc rgb "#d62728" title "lower end (h)", \
     evsel("liftoff") using 1:2 with points pt 9 ps 1.6 lc rgb "#2ca02c" title "liftoff", \
     evsel("impact") using 1:2 with points pt 7 ps 0.8 lc rgb "#000000" title "impact", \
     evsel("landing") using 1:2 with points pt 5 ps 1.2 lc rgb "#ff7f0e" title "landing"
unset title
set xlabel "sim time (s)"
set ylabel "T + U (J)"
plot csv every ::1 using 1:($8 - 0.5 * 0.4 * 0.4) with lines lw 2 lc rgb "#1f77b4" \
     title "T + U - 1/2 m x dot^2 (x dot is constant: frictionless floor)"
unset multiplot
