set terminal pngcairo size 900,560
set output '/work/main/bench/results/scan_blocks.png'
set datafile separator ','
set key top left
set grid
set title 'Block count against time and error (76,503 points)'
set xlabel 'blocks'
set ylabel 'time (ms, wall)'
set y2label 'centerline RMS error / d'
set y2tics
set logscale y2
plot '< grep graph /work/main/bench/results/scan_blocks.csv' using 3:4 with linespoints title 'graph time', '< grep axis /work/main/bench/results/scan_blocks.csv' using 3:4 with linespoints title 'axis time', '< grep graph /work/main/bench/results/scan_blocks.csv' using 3:6 axes x1y2 with linespoints dt 2 title 'graph error', '< grep axis /work/main/bench/results/scan_blocks.csv' using 3:6 axes x1y2 with linespoints dt 2 title 'axis error'
