#!/usr/bin/env bash
# Open3D's multiway registration and sequential ICP beside `nbv register` on the paper's
# Table II case (5 views, 15K points; see open3d_registration.py for the method).
#
#   benches/peers/open3d_registration.sh [VIEWS_DIR] [-- extra options of the .py]
#
# Creates its own virtual environment (target/peers-venv, or $NBV_PEERS_VENV) and installs
# Open3D from PyPI into it (the CPU build `open3d-cpu`, else `open3d`; it needs Debian's
# libgomp1 and libusb-1.0-0 at import). Writes the views with the `registration_views`
# example when VIEWS_DIR (default target/registration-views) has none, builds `nbv` in
# release mode, and prints error against the ground truth and time for every method.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
views=${1:-$root/target/registration-views}
shift || true
[ "${1:-}" = "--" ] && shift

. "$root/benches/peers/open3d_venv.sh"

cd "$root"
if [ ! -f "$views/spec.json" ]; then
    cargo run --release --quiet -p nbv-core --example registration_views -- "$views"
fi
cargo build --release --quiet --bin nbv
exec "$venv/bin/python" "$root/benches/peers/open3d_registration.py" \
    --views "$views" --nbv "$root/target/release/nbv" "$@"
