set terminal svg size 900,600 dynamic font 'sans,13'
set output 'docs/figures/mesh3d_trace_distance_vs_spread.svg'
set title 'Trace distance per update, the octree mesh (mean of each run)'
set xlabel 'log2(L/s)'; set ylabel 'trace events created + undone'
set key right bottom; set grid; set yrange [0:*]
plot '< grep "^clusters-3d " docs/data/mesh3d_spread_means.dat' using 2:3 with linespoints title 'clusters-3d', '< grep "^shrinking-3d " docs/data/mesh3d_spread_means.dat' using 2:3 with linespoints title 'shrinking-3d', '< grep "^uniform-3d " docs/data/mesh3d_spread_means.dat' using 2:3 with linespoints title 'uniform-3d', '< grep "^shrinking-3d " docs/data/spread_means.dat' using 2:3 with linespoints dt 2 title 'shrinking-3d, tree alone'
