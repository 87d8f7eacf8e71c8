set terminal pngcairo size 1500,480
set output '/work/main/bench/results/route.png'
set multiplot layout 1,3 title 'Routing the wing-section harness (24 cables): time budget per segment vs quality; α-SIM 147094→25590 triangles in 17695 ms (seed 20261121)'
set logscale x
set xlabel 'time budget per segment (s)'
set grid
set key top right
set ylabel 'total length / best known'
plot '/work/main/bench/results/route_informedrrtstar.dat' using 1:2 with linespoints title 'informedrrtstar', '/work/main/bench/results/route_rrtconnect.dat' using 1:2 with linespoints title 'rrtconnect', '/work/main/bench/results/route_informedrrtstar-alphasim.dat' using 1:2 with linespoints title 'informedrrtstar-alphasim'
set ylabel 'unrouted + clashes + violations'
plot '/work/main/bench/results/route_informedrrtstar.dat' using 1:3 with linespoints title 'informedrrtstar', '/work/main/bench/results/route_rrtconnect.dat' using 1:3 with linespoints title 'rrtconnect', '/work/main/bench/results/route_informedrrtstar-alphasim.dat' using 1:3 with linespoints title 'informedrrtstar-alphasim'
set ylabel 'planning time (ms)'
set logscale y
plot '/work/main/bench/results/route_informedrrtstar.dat' using 1:4 with linespoints title 'informedrrtstar', '/work/main/bench/results/route_rrtconnect.dat' using 1:4 with linespoints title 'rrtconnect', '/work/main/bench/results/route_informedrrtstar-alphasim.dat' using 1:4 with linespoints title 'informedrrtstar-alphasim'
unset multiplot
