#!/usr/bin/env bash
# Compares nbv's occupancy-grid insertion with OctoMap's on the same paper-scale sweep
# (~55K returns with per-point sensor origins, 2 cm voxels, the same sensor model): builds
# its own Python venv with OctoMap's bindings from PyPI (octomap-python), runs nbv's side
# (core/examples/occupancy_peer.rs, release build) and OctoMap's side
# (octomap_insert.py), and prints both times, their ratio and the agreement of the
# occupied/free classification.
#
# Usage: benches/peers/octomap_insert.sh [OUTDIR] [RUNS]
#   OUTDIR  working directory (default target/peers/octomap)
#   RUNS    timed runs per variant, the median is reported (default 15)
# Environment: NBV_PEER_VENV (default target/peers/octomap-venv), OMP_NUM_THREADS
# (OctoMap's insertPointCloud is parallelised with OpenMP when the wheel was built so).
set -euo pipefail
cd "$(dirname "$0")/../.."

OUT="${1:-target/peers/octomap}"
RUNS="${2:-15}"
VENV="${NBV_PEER_VENV:-target/peers/octomap-venv}"
PYTHON="${PYTHON:-python3}"

if [ ! -x "$VENV/bin/python" ]; then
    echo "creating venv $VENV"
    "$PYTHON" -m venv "$VENV"
fi
if ! "$VENV/bin/python" -c "import octomap, numpy" 2>/dev/null; then
    "$VENV/bin/pip" install --quiet --disable-pip-version-check octomap-python numpy
fi
"$VENV/bin/pip" show octomap-python 2>/dev/null | sed -n 's/^Version: /octomap-python /p'

cargo run --quiet --release -p nbv-core --example occupancy_peer -- "$OUT" --runs "$RUNS"
"$VENV/bin/python" benches/peers/octomap_insert.py "$OUT" --runs "$RUNS"
