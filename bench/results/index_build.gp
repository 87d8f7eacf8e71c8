set terminal pngcairo size 900,500
set output 'index_build.png'
set datafile separator ','
set logscale x
set xlabel 'triangles'
set ylabel 'M triangles / s'
set y2label 'bytes / triangle'
set ytics nomirror
set y2tics
set y2range [0:*]
set yrange [0:*]
set key top right
set title 'Embree BVH build (generated scenes; x = motor.stl)'
plot 'index_build.csv' every ::1::4 using 2:4 with linespoints title 'M tris/s (wall, shared machine)', '' every ::1::4 using 2:6 with linespoints title 'M tris per CPU-second', '' every ::1::4 using 2:7 axes x1y2 with linespoints title 'memory B/tri (right)', '' every ::5::5 using 2:6 with points pt 2 ps 2 title 'motor.stl (per CPU-s)'
