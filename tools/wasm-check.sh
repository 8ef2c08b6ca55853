#!/usr/bin/env bash
# Checks that the library builds for the web: `cargo check -p voxgi` for
# wasm32-unknown-unknown (WebGPU). rustup's toolchain here ships no wasm32 standard library,
# so the standard library is built from Debian's sources: rustc-web (a rustc that targets
# wasm32), rust-web-src (its library sources) and lld-19 (wasm-ld-19). .ci/run installs them;
# elsewhere: apt-get install rustc-web rust-web-src lld-19.
#
#   tools/wasm-check.sh [extra cargo check arguments]
#
# The build goes to target/wasm, apart from the native one (another rustc).
set -euo pipefail
cd "$(dirname "$0")/.."

rustc=/usr/bin/rustc
for need in "$rustc" /usr/bin/wasm-ld-19; do
    if [ ! -x "$need" ]; then
        echo "wasm-check: $need is missing (apt-get install rustc-web rust-web-src lld-19)" >&2
        exit 1
    fi
done
if [ ! -d "$("$rustc" --print sysroot)/lib/rustlib/src/rust/library" ]; then
    echo "wasm-check: the standard library's sources are missing (apt-get install rust-web-src)" >&2
    exit 1
fi

# -Zbuild-std is unstable: RUSTC_BOOTSTRAP lets this stable cargo and rustc take it.
export RUSTC="$rustc" RUSTC_BOOTSTRAP=1
export CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_LINKER=wasm-ld-19
exec cargo check -Zbuild-std=std,panic_abort --target wasm32-unknown-unknown \
    --target-dir target/wasm -p voxgi "$@"
