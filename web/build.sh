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
# tools/wasm-check.sh does. The JavaScript glue comes from voxgi-web's `web-bindgen`,
# wasm-bindgen's generator at the page's own wasm-bindgen version: $WEB_BINDGEN when set (the
# browser test passes the one `cargo test` built), else built here.
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

cd "$root"
flags=()
if [ "$profile" = release ]; then
    flags+=(--release)
fi
# -Zbuild-std is unstable: RUSTC_BOOTSTRAP lets this stable cargo and rustc take it. The build
# goes to target/wasm, apart from the native one (another rustc), shared with wasm-check.sh.
RUSTC="$rustc" RUSTC_BOOTSTRAP=1 CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_LINKER=wasm-ld-19 \
    cargo build -Zbuild-std=std,panic_abort --target wasm32-unknown-unknown \
    --target-dir target/wasm -p voxgi-web --lib "${flags[@]}"

bindgen="${WEB_BINDGEN:-}"
if [ -z "$bindgen" ]; then
    # A native program: the workspace's own target directory and toolchain.
    cargo build --release --quiet -p voxgi-web --bin web-bindgen
    bindgen=target/release/web-bindgen
fi
mkdir -p "$out"
"$bindgen" "target/wasm/wasm32-unknown-unknown/$profile/voxgi_web.wasm" "$out"
cp web/index.html "$out/index.html"
wasm="$out/voxgi_web_bg.wasm"
echo "web/build.sh: wrote $out/index.html ($(du -k "$wasm" | cut -f1) KiB of wasm, $(gzip -c "$wasm" | wc -c | awk '{ printf "%d", $1 / 1024 }') KiB gzipped)"
