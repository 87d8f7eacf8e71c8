set terminal pngcairo size 900,500
set output '/work/main/bench/results/alpha_sim_split.png'
set datafile separator ','
set style data histograms
set style fill solid 0.8
set logscale y
set ylabel 'share of triangles kept (log)'
set xtics rotate by -30
set key top left
set title 'alpha-SIM: triangles kept, blocked parts whole vs split'
plot '/work/main/bench/results/alpha_sim_split.csv' using 7:xtic(1) title 'blocked kept whole', '' using 8 title 'blocked split'
