set terminal pngcairo size 1500,480
set output '/work/main/bench/results/route.png'
set multiplot layout 1,3 title 'Routing the wing-section harness (24 cables): time budget per segment vs quality; α-SIM 147094→3024 triangles in 324 ms (seed 20261121)'
set logscale x
set xrange [0.035:1.5]
set xlabel 'time budget per segment (s)'
set grid
set key top left font ',9'
set ylabel 'total length / best known'
plot '/work/main/bench/results/route_informedrrtstar.dat' using 1:2 with linespoints title 'informedrrtstar', '/work/main/bench/results/route_bitstar.dat' using 1:2 with linespoints title 'bitstar', '/work/main/bench/results/route_rrtstar.dat' using 1:2 with linespoints title 'rrtstar', '/work/main/bench/results/route_prmstar.dat' using 1:2 with linespoints title 'prmstar', '/work/main/bench/results/route_lazyprmstar.dat' using 1:2 with linespoints title 'lazyprmstar', '/work/main/bench/results/route_rrtconnect.dat' using 1:2 with linespoints title 'rrtconnect', '/work/main/bench/results/route_informedrrtstar-alphasim.dat' using 1:2 with linespoints title 'informedrrtstar-alphasim', '/work/main/bench/results/route_bitstar-alphasim.dat' using 1:2 with linespoints title 'bitstar-alphasim'
set ylabel 'unrouted + clashes + violations'
set yrange [-0.5:*]
set offsets 0,0,1,0
plot '/work/main/bench/results/route_informedrrtstar.dat' using 1:3 with linespoints title 'informedrrtstar', '/work/main/bench/results/route_bitstar.dat' using 1:3 with linespoints title 'bitstar', '/work/main/bench/results/route_rrtstar.dat' using 1:3 with linespoints title 'rrtstar', '/work/main/bench/results/route_prmstar.dat' using 1:3 with linespoints title 'prmstar', '/work/main/bench/results/route_lazyprmstar.dat' using 1:3 with linespoints title 'lazyprmstar', '/work/main/bench/results/route_rrtconnect.dat' using 1:3 with linespoints title 'rrtconnect', '/work/main/bench/results/route_informedrrtstar-alphasim.dat' using 1:3 with linespoints title 'informedrrtstar-alphasim', '/work/main/bench/results/route_bitstar-alphasim.dat' using 1:3 with linespoints title 'bitstar-alphasim'
set ylabel 'planning time (ms)'
set autoscale y
set offsets 0,0,0,0
set logscale y
plot '/work/main/bench/results/route_informedrrtstar.dat' using 1:4 with linespoints title 'informedrrtstar', '/work/main/bench/results/route_bitstar.dat' using 1:4 with linespoints title 'bitstar', '/work/main/bench/results/route_rrtstar.dat' using 1:4 with linespoints title 'rrtstar', '/work/main/bench/results/route_prmstar.dat' using 1:4 with linespoints title 'prmstar', '/work/main/bench/results/route_lazyprmstar.dat' using 1:4 with linespoints title 'lazyprmstar', '/work/main/bench/results/route_rrtconnect.dat' using 1:4 with linespoints title 'rrtconnect', '/work/main/bench/results/route_informedrrtstar-alphasim.dat' using 1:4 with linespoints title 'informedrrtstar-alphasim', '/work/main/bench/results/route_bitstar-alphasim.dat' using 1:4 with linespoints title 'bitstar-alphasim'
unset multiplot
