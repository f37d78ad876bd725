# Sourced by the Open3D peer scripts: sets $venv to a virtual environment with Open3D from
# PyPI (target/peers-venv, or $NBV_PEERS_VENV), creating it on first use (the CPU build
# `open3d-cpu`, else `open3d`; it needs Debian's libgomp1 and libusb-1.0-0 at import).
# Expects $root, the repository's top directory.
venv=${NBV_PEERS_VENV:-$root/target/peers-venv}
if ! "$venv/bin/python" -c 'import open3d' 2>/dev/null; then
    python3 -m venv "$venv"
    "$venv/bin/pip" install --quiet --upgrade pip
    "$venv/bin/pip" install --quiet open3d-cpu || "$venv/bin/pip" install --quiet open3d
fi
