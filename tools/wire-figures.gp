# wire-figures.gp -- the review's Figures 8 and 9 for the elastic wire
# (docs/NURBS.md) from the midpoint tables tools/wire-midpoint writes:
#   gnuplot -e "data='build/wire-data'; out='docs'" tools/wire-figures.gp

if (!exists("data")) data = 'build/wire-data'
if (!exists("out")) out = 'docs'
f(name) = sprintf('%s/%s', data, name)

set terminal pngcairo size 900,520 font 'sans,10'
set grid
set xlabel 't (s)'
set ylabel 'height of the midpoint c(0.5) (m)'
set key below

set output sprintf('%s/nurbs-figure8.png', out)
set title 'Elastic wire (review, Figure 8): midpoint from rest at y = 5, alpha 35, beta 10, mu 30, dt 0.008 s'
plot f('gamma0.dat') using 1:3 with lines lw 2 title 'gamma = 0, leapfrog', \
     f('gamma5.dat') using 1:3 with lines lw 2 title 'gamma = 5, leapfrog', \
     f('gamma0-review.dat') using 1:3 with lines dt 2 title 'gamma = 0, the review''s scheme (numerical damping)', \
     f('gamma5-review.dat') using 1:3 with lines dt 3 title 'gamma = 5, the review''s scheme'

set output sprintf('%s/nurbs-figure9.png', out)
set xrange [0:8]
set key below
set multiplot layout 1,2 title 'Sensitivity to alpha and beta (review, Figure 9): gamma = 0, leapfrog, dt 0.008 s'
set title 'beta = 10'
plot f('alpha10.dat') using 1:3 with lines title 'alpha = 10', \
     f('gamma0.dat') using 1:3 with lines title 'alpha = 35', \
     f('alpha100.dat') using 1:3 with lines title 'alpha = 100'
set title 'alpha = 35'
plot f('beta1.dat') using 1:3 with lines title 'beta = 1', \
     f('gamma0.dat') using 1:3 with lines title 'beta = 10', \
     f('beta50.dat') using 1:3 with lines title 'beta = 50 (dt 0.004 s)'
unset multiplot
