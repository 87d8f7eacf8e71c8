set terminal pngcairo size 900,560
set output '/work/main/bench/results/scan_noise.png'
set datafile separator ','
set key top left
set grid
set title 'Centerline error against scan noise (76,503 points, d = 2)'
set xlabel 'noise sigma / d'
set ylabel 'centerline RMS error / d'
set logscale y
plot '/work/main/bench/results/scan_noise.csv' every ::1 using 1:2 with linespoints title 'graph (given d)', '' every ::1 using 1:4 with linespoints title 'graph (estimated d)', '' every ::1 using 1:3 with linespoints title 'axis slabs (paper)', 0.02 with lines dt 2 title '2% d'
