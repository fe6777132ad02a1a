#!/usr/bin/env bash
# Build tests/consumer against the library installed into the build tree.
#
#   consumer_test.sh install BUILD_DIR PREFIX     cmake --install BUILD_DIR --prefix PREFIX
#   consumer_test.sh cmake SOURCE_DIR PREFIX WORK find_package(friction), build, run
#   consumer_test.sh pkg-config SOURCE_DIR PREFIX WORK  cc $(pkg-config ...), build, run
set -euo pipefail

case "$1" in
  install)
    rm -rf "$3"
    cmake --install "$2" --prefix "$3" > /dev/null
    # The installed program finds the installed shared library.
    "$3/bin/friction" --version
    # The parallel program the serial one hands launched runs to, beside it.
    "$3/bin/friction-mpi" --version | grep -q 'HDF5 .*(parallel)'
    ;;
  cmake)
    rm -rf "$4"
    cmake -S "$2" -B "$4" -DCMAKE_PREFIX_PATH="$3" > /dev/null
    cmake --build "$4" > /dev/null
    "$4/consumer"
    ;;
  pkg-config)
    rm -rf "$4"
    mkdir -p "$4"
    export PKG_CONFIG_PATH="$(dirname "$(find "$3" -name friction.pc)")"
    libdir=$(pkg-config --variable=libdir friction)
    # Only -lfriction: the shared library carries HDF5, MPI, GSL and FFTW.
    cc -o "$4/consumer" "$2/consumer.c" $(pkg-config --cflags --libs friction) -Wl,-rpath,"$libdir"
    "$4/consumer"
    ;;
  *)
    echo "usage: $0 install|cmake|pkg-config ..." >&2
    exit 2
    ;;
esac
