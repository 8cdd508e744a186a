set terminal svg size 900,600 dynamic font 'sans,13'
set output 'docs/figures/mesh3d_update_time_vs_n.svg'
set title 'Update time and trace distance, the octree mesh (shrinking, L/s = 2^{20})'
set xlabel 'n'; set logscale x; set ylabel 'mean update time (µs)'; set y2label 'mean trace distance'
set y2tics; set ytics nomirror; set key left bottom; set grid; set yrange [0:*]; set y2range [0:*]
plot '< grep "^3d " docs/data/mesh3d_size_means.dat' using 2:3 with linespoints title '3D time', '< grep "^3d " docs/data/mesh3d_size_means.dat' using 2:4 axes x1y2 with linespoints dt 2 title '3D distance'
