#!/bin/sh
# Builds bench_cgal_hausdorff outside the repository, for `cargo bench --bench hausdorff`.
# Needs Debian's libcgal-dev (CGAL 5.5, header-only) and g++: `apt-get install libcgal-dev`.
# The binary goes to $OBBTREE_PEERS (default /tmp/peers), where the benchmark looks for it.
set -eu
out="${OBBTREE_PEERS:-/tmp/peers}"
mkdir -p "$out"
here="$(cd "$(dirname "$0")" && pwd)"
g++ -std=c++17 -O2 -DNDEBUG -DCGAL_NDEBUG "$here/bench_cgal_hausdorff.cpp" -o "$out/bench_cgal_hausdorff" -lgmp -lmpfr
echo "built $out/bench_cgal_hausdorff"
