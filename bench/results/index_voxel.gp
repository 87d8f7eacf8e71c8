set terminal pngcairo size 900,500
set output 'index_voxel.png'
set datafile separator ','
set logscale x
set xrange [1:16]
set xlabel 'voxel edge (mm)'
set ylabel 'distance error (mm)'
set y2label 'query time per CPU (ns, log)'
set logscale y2
set ytics nomirror
set y2tics
set key top left
set title 'Voxel distance map: voxel size vs error and lookup time (100k triangles)'
plot 'index_voxel.csv' every ::1 using 1:8 with linespoints title 'max |error|', '' every ::1 using 1:9 with linespoints title 'mean |error|', '' every ::1 using 1:10 with lines dashtype 2 title 'stated bound (half diagonal)', '' every ::1 using 1:(1e9/$14) axes x1y2 with linespoints title 'lookup ns (1 thread, per CPU-s)', '' every ::1 using 1:(1e9/$13) axes x1y2 with lines dashtype 3 title 'exact Embree closest ns (per CPU-s)'
