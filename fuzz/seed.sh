#!/usr/bin/env bash
# Fills fuzz/corpus/<target>/ with seed files: fuzz/seeds, the repository's examples, and the real scenes'
# files (under 1 MiB; the office scan's 1.8 MiB PCD too) when ../shared/scenes is present. Run from the repository root.
set -euo pipefail
cd "$(dirname "$0")/.."
for target in gltf ply pcd obj cloud toml; do
    mkdir -p "fuzz/corpus/$target"
done
copy() { # $1: target, $2...: file name patterns
    local target=$1
    shift
    for pattern in "$@"; do
        find fuzz/seeds examples ../shared/scenes -name "$pattern" \( -size -1024k -o -name office1.pcd \) 2>/dev/null | while read -r f; do
            cp "$f" "fuzz/corpus/$target/$(echo "${f#../}" | tr '/' '_')"
        done
    done
}
copy gltf '*.gltf' '*.glb'
copy ply '*.ply'
copy pcd '*.pcd'
copy obj '*.obj'
copy cloud '*.cloud'
copy toml '*.toml'
for target in gltf ply pcd obj cloud toml; do
    echo "$target: $(ls -A "fuzz/corpus/$target" | wc -l) seeds"
done
