# afm_maps.gp: the lateral force maps Fx and Fy of a friction output file,
# side by side in one PNG, with gnuplot alone (no Python).  The gnuplot
# counterpart of the maps from plot_afm.py (paper Fig. 7b/8b).
#
# Route: afm_maps_gnuplot.sh extracts /afm/support_x, /afm/support_y and
# /afm/<trip>/fx, fy with h5dump into one plain-text table and calls
#
#   gnuplot -c afm_maps.gp DATA OUT.png [TITLE]
#
# DATA has four columns, one row per sample, a blank line after each scan
# line (gnuplot's grid format):
#   support_x (Å, along the scan)  support_y (Å, across it)  Fx (nN)  Fy (nN)
# Any other tool that writes this table can feed the script too.  TITLE is
# the figure title (default: DATA).  Colour scales are symmetric about 0 nN;
# both axes are drawn to the same scale, so a 20×20 Å scan is square.

if (ARGC < 2) {
    print "usage: gnuplot -c afm_maps.gp DATA OUT.png [TITLE]"
    exit status 2
}
data = ARG1
out = ARG2
title = (ARGC >= 3) ? ARG3 : data

set encoding utf8
# pngcairo where gnuplot has it (gnuplot-nox does), else the libgd png terminal
if (strstrt(GPVAL_TERMINALS, "pngcairo") > 0) {
    set terminal pngcairo size 1500,650 enhanced font ",12"
} else {
    set terminal png size 1500,650 enhanced font ",12"
}
set output out

# a blue-white-red map like matplotlib's RdBu_r
set palette defined (0 "#053061", 0.2 "#4393c3", 0.5 "#f7f7f7", 0.8 "#d6604d", 1 "#67001f")
set size ratio -1
set tics out nomirror
set xlabel "support position along the scan (Å)"
set ylabel "line offset across the scan (Å)"
set cbtics out
set key off

# All stats before any range is set: stats honours the current ranges.
# Pixel centres sit on the support positions: extend the axes half a pixel
# (for "every", the blocks are the scan lines, split by single blank lines).
stats data using 1 every ::0::1 nooutput
dx = STATS_max - STATS_min
stats data using 1 nooutput
x0 = STATS_min; x1 = STATS_max
stats data using 2 every ::0::0 nooutput
y0 = STATS_min; y1 = STATS_max
dy = (STATS_records > 1) ? (y1 - y0) / (STATS_records - 1) : dx
# colour scales symmetric about 0 nN: the largest |F| of each map
array limit[4]
do for [col = 3:4] {
    stats data using col nooutput
    limit[col] = (abs(STATS_min) > abs(STATS_max)) ? abs(STATS_min) : abs(STATS_max)
    limit[col] = (limit[col] > 0) ? limit[col] : 1.0
}
set xrange [x0 - dx / 2 : x1 + dx / 2]
set yrange [y0 - dy / 2 : y1 + dy / 2]

set multiplot layout 1, 2 title title font ",14" noenhanced
do for [col = 3:4] {
    set cbrange [-limit[col] : limit[col]]
    name = (col == 3) ? "F_x" : "F_y"
    set title sprintf("%s (lattice %s axis)", name, (col == 3) ? "x" : "y") font ",13"
    set cblabel sprintf("%s (nN)", name)
    # a single scan line is too thin for "with image": draw boxes instead
    if (y1 > y0) {
        plot data using 1:2:col with image
    } else {
        plot data using 1:2:(dx / 2):(dy / 2):col \
            with boxxyerror fillstyle solid noborder lc palette
    }
}
unset multiplot
set output
