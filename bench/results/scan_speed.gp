set terminal pngcairo size 900,560
set output '/work/main/bench/results/scan_speed.png'
set datafile separator ','
set key top left
set grid
set title 'Scan centerline throughput (curve3d, d = 2, sigma = 1% d)'
set ylabel 'points / s (wall)'
set style data histograms
set style fill solid 0.8
set xtics rotate by -20
set logscale y
plot '< grep -v points /work/main/bench/results/scan_speed.csv' using 6:xtic(sprintf('%s n=%d t=%d',strcol(2),$1,$3)) title 'points/s' lc rgb '#3070b0', 1e6 with lines dt 2 lc rgb 'red' title 'target 1 M/s'
