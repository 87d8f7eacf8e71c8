set terminal pngcairo size 1200,500
set output '/work/main/bench/results/planner.png'
set multiplot layout 1,2 title 'Planner speed vs quality: 300 boxes, 6 cables, tube r=3 c=2 (fixed seeds)'
set logscale x
set xlabel 'time budget (s)'
set key top right
set grid
set ylabel 'mean length / best known length (solved cables)'
plot '/work/main/bench/results/planner_rrtconnect.dat' using 1:2 with linespoints title 'rrtconnect', '/work/main/bench/results/planner_rrtstar.dat' using 1:2 with linespoints title 'rrtstar', '/work/main/bench/results/planner_informedrrtstar.dat' using 1:2 with linespoints title 'informedrrtstar', '/work/main/bench/results/planner_bitstar.dat' using 1:2 with linespoints title 'bitstar', '/work/main/bench/results/planner_prmstar.dat' using 1:2 with linespoints title 'prmstar', '/work/main/bench/results/planner_lazyprmstar.dat' using 1:2 with linespoints title 'lazyprmstar'
set ylabel 'failures (of 6)'
set yrange [0:6]
plot '/work/main/bench/results/planner_rrtconnect.dat' using 1:3 with linespoints title 'rrtconnect', '/work/main/bench/results/planner_rrtstar.dat' using 1:3 with linespoints title 'rrtstar', '/work/main/bench/results/planner_informedrrtstar.dat' using 1:3 with linespoints title 'informedrrtstar', '/work/main/bench/results/planner_bitstar.dat' using 1:3 with linespoints title 'bitstar', '/work/main/bench/results/planner_prmstar.dat' using 1:3 with linespoints title 'prmstar', '/work/main/bench/results/planner_lazyprmstar.dat' using 1:3 with linespoints title 'lazyprmstar'
unset multiplot
