#!/usr/bin/env bash
# Builds voxgi's web page into DIR: index.html, voxgi_web.js and voxgi_web_bg.wasm.
#
#   web/build.sh DIR [--debug]
#
# Serve DIR over http (web/serve.sh DIR) and open it in a browser with WebGPU; the query
# string picks a built-in scene and settings: index.html?builtin=two-rooms&bounces=1.
#
# rustup's toolchain here ships no wasm32 standard library, so it is built from Debian's
# sources: rustc-web (a rustc that targets wasm32), rust-web-src and lld-19 (wasm-ld-19), as
# tools/wasm-check.sh does. wasm-bindgen-cli must be the version Cargo.lock pins for
# wasm-bindgen (the two must match); it is installed with cargo when missing.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
if [ $# -lt 1 ] || [ "${1#-}" != "$1" ]; then
    echo "usage: web/build.sh DIR [--debug]" >&2
    exit 2
fi
out="$1"
profile=release
if [ "${2:-}" = "--debug" ]; then
    profile=debug
fi

rustc=/usr/bin/rustc
for need in "$rustc" /usr/bin/wasm-ld-19; do
    if [ ! -x "$need" ]; then
        echo "web/build.sh: $need is missing (apt-get install rustc-web rust-web-src lld-19)" >&2
        exit 1
    fi
done
if [ ! -d "$("$rustc" --print sysroot)/lib/rustlib/src/rust/library" ]; then
    echo "web/build.sh: the standard library's sources are missing (apt-get install rust-web-src)" >&2
    exit 1
fi

# The wasm-bindgen Cargo.lock pins.
version="$(awk '/^name = "wasm-bindgen"$/ { getline; gsub(/version = |"/, ""); print; exit }' \
    "$root/Cargo.lock")"
if [ -z "$version" ]; then
    echo "web/build.sh: Cargo.lock pins no wasm-bindgen" >&2
    exit 1
fi
bindgen="$(command -v wasm-bindgen || true)"
if [ -z "$bindgen" ] || [ "$("$bindgen" --version | awk '{ print $2 }')" != "$version" ]; then
    echo "web/build.sh: installing wasm-bindgen-cli $version (it must match Cargo.lock's wasm-bindgen)"
    # Not --locked: the CLI's own lock file names a crate version the registry no longer has.
    # --force: a missing binary with its install record left behind is installed again too.
    cargo install --quiet --force wasm-bindgen-cli --version "$version"
    bindgen="$(command -v wasm-bindgen || echo "$HOME/.cargo/bin/wasm-bindgen")"
fi

cd "$root"
flags=()
if [ "$profile" = release ]; then
    flags+=(--release)
fi
# -Zbuild-std is unstable: RUSTC_BOOTSTRAP lets this stable cargo and rustc take it. The build
# goes to target/wasm, apart from the native one (another rustc), shared with wasm-check.sh.
RUSTC="$rustc" RUSTC_BOOTSTRAP=1 CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_LINKER=wasm-ld-19 \
    cargo build -Zbuild-std=std,panic_abort --target wasm32-unknown-unknown \
    --target-dir target/wasm -p voxgi-web "${flags[@]}"

mkdir -p "$out"
"$bindgen" --target web --no-typescript --out-dir "$out" \
    "target/wasm/wasm32-unknown-unknown/$profile/voxgi_web.wasm"
cp web/index.html "$out/index.html"
wasm="$out/voxgi_web_bg.wasm"
echo "web/build.sh: wrote $out/index.html ($(du -k "$wasm" | cut -f1) KiB of wasm, $(gzip -c "$wasm" | wc -c | awk '{ printf "%d", $1 / 1024 }') KiB gzipped)"
