#!/usr/bin/env bash
# Open3D's TSDF fusion (tensor VoxelBlockGrid) beside `nbv fuse` on the same exported views of
# each object, both meshes scored by the same code (see open3d_tsdf.py).
#
#   benches/peers/open3d_tsdf.sh RUN_DIR... [-- extra options of the .py]
#
# RUN_DIR: an `nbv explore` output (objects/<name>/rgbd/ and truth.stl). Creates its own
# virtual environment (target/peers-venv, or $NBV_PEERS_VENV) with Open3D from PyPI, as
# open3d_registration.sh does, and builds `nbv` in release mode.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
runs=()
while [ $# -gt 0 ] && [ "$1" != "--" ]; do
    [ -d "$1" ] || { echo "error: $1: no such run directory" >&2; exit 2; }
    runs+=("$(cd "$1" && pwd)"); shift
done
[ "${1:-}" = "--" ] && shift

. "$root/benches/peers/open3d_venv.sh"
cd "$root"
cargo build --release --quiet --bin nbv
exec "$venv/bin/python" "$root/benches/peers/open3d_tsdf.py" "${runs[@]}" \
    --nbv "$root/target/release/nbv" "$@"
