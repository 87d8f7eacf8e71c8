set terminal pngcairo size 800,500
set output 'index_build.png'
set datafile separator ','
set logscale x
set xlabel 'triangles'
set ylabel 'M triangles / s'
set y2label 'bytes / triangle'
set ytics nomirror
set y2tics
set key top left
set title 'Embree BVH build rate and memory'
plot 'index_build.csv' every ::1 using 2:4 with linespoints title 'build rate (M tris/s)', '' every ::1 using 2:5 axes x1y2 with linespoints title 'memory (B/tri)'
