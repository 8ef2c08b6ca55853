#!/usr/bin/env bash
# Serves a folder web/build.sh wrote on http://localhost:PORT/ (default 8000) with Python's
# http.server; open it in a browser with WebGPU.
#
#   web/serve.sh DIR [PORT]
set -euo pipefail
if [ $# -lt 1 ] || [ ! -f "$1/index.html" ]; then
    echo "usage: web/serve.sh DIR [PORT] (DIR as web/build.sh wrote it)" >&2
    exit 2
fi
port="${2:-8000}"
echo "web/serve.sh: http://localhost:$port/ (Ctrl-C stops)"
exec python3 -m http.server "$port" --bind 127.0.0.1 --directory "$1"
