# bench.gp -- the plots of docs/PERFORMANCE.md and docs/ACCURACY.md from the
# data files tools/bench.c writes (make bench):
#   gnuplot -e "data='build/bench-data'; out='docs'" tools/bench.gp

if (!exists("data")) data = 'build/bench-data'
if (!exists("out")) out = 'docs'
f(name) = sprintf('%s/%s', data, name)

set terminal pngcairo size 800,520 font 'sans,10'
set grid
set key top right

# Accuracy against cost: one point per node count (columns as in quadrature.dat);
# cost as the time ratio to 8 nodes, which is robust on a shared machine.
pos(x) = x > 0 ? x : NaN
set output sprintf('%s/accuracy-quadrature.png', out)
set title 'Quadrature nodes per segment: error against cost (annealed study scene; labels: nodes)'
set xlabel 'time per proposal, relative to 8 nodes'
set ylabel 'relative error against 64 nodes'
set logscale xy
set format y '10^{%L}'
set key bottom left
plot f('quadrature.dat') using 3:(pos($5)) with linespoints pt 7 title 'pair energy', \
     '' using 3:(pos($6)) with linespoints pt 5 title 'bending energy', \
     '' using 3:(pos($7)) with linespoints pt 13 title 'dE of proposals (median)', \
     '' using 3:(pos($9)) with linespoints pt 11 title 'share of decisions that differ', \
     '' using 3:(pos($7)):(sprintf('%d', $1)) with labels offset 0,1 notitle

# The cutoff: errors against no cutoff (left) and cost (right) against the cutoff.
set output sprintf('%s/accuracy-cutoff.png', out)
set title 'Pair cutoff: difference from no cutoff, and cost (annealed study scene)'
set xlabel 'cutoff, line spacings'
set ylabel 'relative difference from no cutoff'
set y2label 'time per proposal, relative to a 4 mm cutoff'
unset logscale y
set format y '%g'
set yrange [0:1.05]
set y2range [0:*]
set ytics nomirror
set y2tics
set key left center
plot f('cutoff.dat') using 2:6 with linespoints pt 13 title 'dE of the pair term (median)', \
     '' using 2:8 with linespoints pt 11 title 'share of decisions that differ', \
     '' using 2:5 with linespoints pt 7 title 'pair energy', \
     '' using 2:4 axes x1y2 with linespoints pt 5 lw 2 title 'time (right axis)'
unset y2tics
unset y2label
set ytics mirror
set autoscale y

# Scaling: cost per proposal and memory against the number of splines.
set output sprintf('%s/scaling.png', out)
set title 'Cost per proposal and memory at constant density'
set xlabel 'splines'
set ylabel 'ns per proposal'
set y2label 'bytes per segment'
unset format y
set logscale x
unset logscale y
set yrange [0:*]
set y2range [0:*]
set y2tics
set ytics nomirror
set key center right
set logscale y
set yrange [*:*]
plot f('scaling.dat') index 0 using 2:3 with linespoints pt 7 title 'ns per proposal, local terms', \
     '' index 1 using 2:3 with linespoints pt 5 title 'ns per proposal, with the pair term', \
     '' index 0 using 2:5 axes x1y2 with linespoints pt 4 dt 2 title 'bytes per segment, local terms', \
     '' index 1 using 2:5 axes x1y2 with linespoints pt 6 dt 2 title 'bytes per segment, with the pair term'
unset logscale y
unset y2tics
unset y2label
set ytics mirror
set autoscale y

# Baseline: lowest energy found against wall time, both annealers, each size.
set output sprintf('%s/baseline.png', out)
set title 'linewise against gsl\_siman\_solve: the lowest energy found, from the same start'
set xlabel 'wall time, s'
set ylabel 'change of the energy per spline'
set logscale x
set xrange [0.01:*]
set format x '%g'
set key bottom left
load f('baseline.gp')   # sizes = '100 1000 ...', written by the benchmark
plot for [i = 1:words(sizes)] f(sprintf('baseline-%s.dat', word(sizes, i))) index 0 using 1:3 \
       with lines lw 2 lc i title sprintf('linewise, %s splines', word(sizes, i)), \
     for [i = 1:words(sizes)] f(sprintf('baseline-%s.dat', word(sizes, i))) index 1 using 1:3 \
       with lines lw 2 dt 2 lc i title sprintf('gsl\_siman, %s splines', word(sizes, i))
