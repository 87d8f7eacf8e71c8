set terminal pngcairo size 1200,450 noenhanced
set output '/work/main/bench/results/alpha_sim_tessellation.png'
set datafile separator ','
set key top left
set multiplot layout 1,2 title 'alpha-SIM on the wing-section CAD files at four tessellations (dim_pre = 8 mm)'
set logscale x
set xlabel 'input triangles'
set grid
set ylabel 'clearance queries/s: simplified / original'
plot '/work/main/bench/results/alpha_sim_tessellation.csv' using 3:10 with linespoints title 'in the box', '' using 3:13 with linespoints title 'near the surface', 5 with lines dashtype 2 title 'target 5x'
set ylabel 'input triangles/s (2 threads)'
set logscale y
set yrange [1e4:2e6]
plot '' using 3:6 with linespoints title 'throughput', 1e6 with lines dashtype 2 title 'target 1e6/s'
unset multiplot
