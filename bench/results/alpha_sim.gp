set terminal pngcairo size 1200,800
set output '/work/main/bench/results/alpha_sim.png'
set datafile separator ','
set key autotitle columnhead
set multiplot layout 2,2 title 'alpha-SIM on occt/motor.stl (13,502 triangles): level of detail dim_pre'
set logscale x
set xlabel 'dim_pre / bbox diagonal'
set grid
set ylabel 'triangles after / before (%)'
plot '/work/main/bench/results/alpha_sim_sweep.csv' using 2:($4*100) with linespoints title 'triangle ratio'
set ylabel 'Hausdorff / diagonal'
plot '' using 2:6 with linespoints title 'one-sided Hausdorff'
set ylabel 'time (ms)'
plot '' using 2:7 with linespoints title 'simplification time'
set ylabel 'queries/s: simplified / original'
set logscale y
plot '' using 2:9 with linespoints title 'closest within 5% diag', '' using 2:11 with linespoints title 'clearance r = dim_pre, in the box', '' using 2:12 with linespoints title 'clearance r = dim_pre, near the surface'
unset multiplot
