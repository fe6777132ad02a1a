#!/bin/sh
# afm_maps_gnuplot.sh: the Fx and Fy maps of a friction output file as one
# PNG, with h5dump and gnuplot only (no Python): the gnuplot route to the
# maps that plot_afm.py draws with matplotlib.
#
#   afm_maps_gnuplot.sh FILE.h5 [OUT.png [trace|retrace]]
#
# OUT.png defaults to <stem of FILE>_maps_gnuplot.png in the current
# directory; the trip to trace.  Route:
#   1. h5dump -y -w 0 -m %.10g -d DATASET -o TMP FILE.h5 writes the bare
#      values of /afm/support_x, /afm/support_y, /afm/<trip>/fx and fy to
#      temporary text files (comma-separated; the line layout varies with
#      h5dump's options, so it is not relied on);
#   2. awk splits them into one number per line and joins them into the
#      table afm_maps.gp reads: "x y Fx Fy" per sample, a blank line after
#      each scan line (datasets are (ny, nx), row-major);
#   3. gnuplot -c afm_maps.gp TABLE OUT.png TITLE draws both maps; the title
#      names the potential and the scan angle (h5dump -a of /afm's attributes).
# Needs h5dump (Debian: hdf5-tools) and gnuplot with the pngcairo terminal
# (gnuplot-nox); H5DUMP and GNUPLOT in the environment override the programs.
# Exit codes: 0 done, 1 h5dump or gnuplot failed, 2 bad arguments or input.

set -eu

prog=afm_maps_gnuplot.sh
H5DUMP=${H5DUMP:-h5dump}
GNUPLOT=${GNUPLOT:-gnuplot}

usage="usage: $prog FILE.h5 [OUT.png [trace|retrace]]"
case ${1:-} in
    -h | --help) echo "$usage"; exit 0 ;;
esac
if [ $# -lt 1 ] || [ $# -gt 3 ]; then
    echo "$usage" >&2
    exit 2
fi
in=$1
stem=$(basename "$in")
out=${2:-${stem%.*}_maps_gnuplot.png}
trip=${3:-trace}
case $trip in
    trace | retrace) ;;
    *) echo "$prog: trip must be trace or retrace, not '$trip'" >&2; exit 2 ;;
esac
fail() { echo "$prog: $in: $1" >&2; exit 2; }
[ -e "$in" ] || fail "no such file"
[ -f "$in" ] || fail "not a regular file"

for tool in "$H5DUMP" "$GNUPLOT"; do
    command -v "$tool" >/dev/null 2>&1 ||
        { echo "$prog: $tool not found (Debian: hdf5-tools, gnuplot-nox)" >&2; exit 1; }
done
gp=$(dirname "$0")/afm_maps.gp
tmp=$(mktemp -d "${TMPDIR:-/tmp}/afm_maps.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
trap 'exit 1' INT TERM

# text attribute or scalar of FILE: the DATA line of h5dump's listing
attribute() {
    "$H5DUMP" -y -a "$1" "$in" 2>/dev/null |
        awk '/DATA \{/ { getline; sub(/^[ \t]*(\([0-9]+\): *)?/, ""); gsub(/[ \t]+$|"/, "")
                          print; exit }'
}
# dataset -> one number per line in $tmp/$2
dump() {
    "$H5DUMP" -y -w 0 -m %.10g -d "$1" -o "$tmp/raw" "$in" >/dev/null 2>&1 ||
        fail "no dataset $1${3:-}"
    awk '{ gsub(/,/, " "); for (i = 1; i <= NF; i++) print $i }' "$tmp/raw" >"$tmp/$2"
}

"$H5DUMP" -H "$in" >/dev/null 2>&1 || fail "not an HDF5 file h5dump can read"
[ "$(attribute /program)" = friction ] && [ "$(attribute /scene)" = afm ] ||
    fail "not a friction force-map file (needs program = 'friction', scene = 'afm')"
dump /afm/support_x x
dump /afm/support_y y
hint=
[ "$trip" = retrace ] && hint=" (the run had retrace off?)"
dump "/afm/$trip/fx" fx "$hint"
dump "/afm/$trip/fy" fy "$hint"

# join: file 1 and 2 are the axes, 3 and 4 the (ny, nx) maps
awk 'FNR == 1 { f++ }
     f == 1 { x[nx++] = $1 } f == 2 { y[ny++] = $1 }
     f == 3 { fx[n3++] = $1 } f == 4 { fy[n4++] = $1 }
     END {
         if (nx < 1 || ny < 1 || n3 != nx * ny || n4 != nx * ny) {
             printf "maps hold %d and %d values, axes %d x %d\n", n3, n4, ny, nx > "/dev/stderr"
             exit 1
         }
         for (j = 0; j < ny; j++) {
             for (i = 0; i < nx; i++) print x[i], y[j], fx[j * nx + i], fy[j * nx + i]
             print ""
         }
     }' "$tmp/x" "$tmp/y" "$tmp/fx" "$tmp/fy" >"$tmp/maps.dat" ||
    fail "maps and axes do not match"

potential=$(attribute /afm/potential)
case $potential in
    naf) potential="NaF(001)" ;;
    hopg) potential=HOPG ;;
esac
angle=$(attribute /afm/angle)
title="Lateral force maps, $trip: $potential, scan angle ${angle}°"

"$GNUPLOT" -c "$gp" "$tmp/maps.dat" "$out" "$title" || {
    echo "$prog: gnuplot failed on $in" >&2
    exit 1
}
echo "wrote $out"
