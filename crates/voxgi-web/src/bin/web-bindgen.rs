//! Writes the web page's JavaScript glue and its final wasm, as `wasm-bindgen --target web
//! --no-typescript --out-dir OUT WASM` does (web/build.sh runs it).
//!
//!     web-bindgen WASM OUT
//!
//! A native program: built for wasm32 (where the page is) it does nothing.

#[cfg(not(target_arch = "wasm32"))]
fn main() -> anyhow::Result<()> {
    use anyhow::{Context, bail};
    use std::path::PathBuf;

    let args: Vec<PathBuf> = std::env::args_os().skip(1).map(PathBuf::from).collect();
    let [wasm, out] = args.as_slice() else {
        bail!("usage: web-bindgen WASM OUT (the page's .wasm from cargo, the folder to write)");
    };
    if !wasm.is_file() {
        bail!(
            "{}: no such file (build voxgi-web for wasm32 first)",
            wasm.display()
        );
    }
    wasm_bindgen_cli_support::Bindgen::new()
        .input_path(wasm)
        .web(true)?
        .typescript(false)
        // The page's index.html calls init() with no path: the glue finds the wasm beside it.
        .omit_default_module_path(false)
        .generate(out)
        .with_context(|| format!("wasm-bindgen's glue for {}", wasm.display()))?;
    Ok(())
}

#[cfg(target_arch = "wasm32")]
fn main() {}
