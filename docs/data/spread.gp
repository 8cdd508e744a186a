set terminal svg size 900,600 dynamic font 'sans,13'
set output 'docs/figures/trace_distance_vs_spread.svg'
set title 'Trace distance per update, the quadtree (mean of each run)'
set xlabel 'log2(L/s)'; set ylabel 'trace events created + undone'
set key right bottom; set grid; set yrange [0:*]
plot '< grep "^clusters-2d " docs/data/spread_means.dat' using 2:3 with linespoints title 'clusters-2d', '< grep "^shrinking-2d " docs/data/spread_means.dat' using 2:3 with linespoints title 'shrinking-2d', '< grep "^shrinking-3d " docs/data/spread_means.dat' using 2:3 with linespoints title 'shrinking-3d', '< grep "^spiral-2d " docs/data/spread_means.dat' using 2:3 with linespoints title 'spiral-2d', '< grep "^uniform-2d " docs/data/spread_means.dat' using 2:3 with linespoints title 'uniform-2d'
