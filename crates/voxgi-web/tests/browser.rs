//! The web page in a real browser: web/build.sh builds it (wasm32, Debian's rustc-web), and
//! web/test_page.py opens it in headless Chromium (WebGPU on SwiftShader) and checks the
//! picture, the camera, the panel, both structures, the split view with the path tracer,
//! files opened from the page, the console, and the resolution lowered under WebGPU's default
//! limits (its docstring says what and why). Skipped, with the reason, when a tool is missing; under `CI` (which installs
//! them all) a missing tool fails the test.

use std::path::{Path, PathBuf};
use std::process::Command;

fn chromium() -> PathBuf {
    std::env::var_os("CHROMIUM").map_or_else(|| PathBuf::from("/usr/bin/chromium"), PathBuf::from)
}

/// What the build and the browser test need and this machine lacks.
fn missing_tools() -> Vec<String> {
    let mut missing = Vec::new();
    let wasm_rustc = Command::new("/usr/bin/rustc")
        .args(["--print", "target-list"])
        .output()
        .is_ok_and(|o| String::from_utf8_lossy(&o.stdout).contains("wasm32-unknown-unknown"));
    if !wasm_rustc {
        missing.push("Debian's rustc-web (/usr/bin/rustc with wasm32)".to_string());
    }
    if !Path::new("/usr/bin/wasm-ld-19").exists() {
        missing.push("lld-19 (wasm-ld-19)".to_string());
    }
    if !chromium().exists() {
        missing.push(format!("chromium ({})", chromium().display()));
    }
    let python = Command::new("python3")
        .args(["-c", "import playwright.sync_api, PIL"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !python {
        missing.push("python3 with playwright and pillow (pip install playwright pillow)".into());
    }
    missing
}

#[test]
fn the_web_page_renders_the_cornell_box_in_chromium() {
    let missing = missing_tools();
    if !missing.is_empty() {
        let what = missing.join(", ");
        assert!(
            std::env::var_os("CI").is_none(),
            "the browser test needs {what} (CI installs them)"
        );
        eprintln!("skipped: the browser test needs {what}");
        return;
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let out = std::env::temp_dir().join(format!("voxgi-web-test-{}", std::process::id()));
    let built = Command::new("bash")
        .arg(root.join("web/build.sh"))
        .arg(&out)
        // The glue generator `cargo test` built with the workspace: no second native build.
        .env("WEB_BINDGEN", env!("CARGO_BIN_EXE_web-bindgen"))
        .status()
        .expect("bash runs web/build.sh");
    assert!(built.success(), "web/build.sh failed ({built})");
    let shots = out.join("shots");
    std::fs::create_dir_all(&shots).expect("a folder for the screenshots");
    let run = Command::new("python3")
        .arg(root.join("web/test_page.py"))
        .arg(&out)
        .arg("--out")
        .arg(&shots)
        .arg("--chromium")
        .arg(chromium())
        .output()
        .expect("python3 runs web/test_page.py");
    let stdout = String::from_utf8_lossy(&run.stdout);
    let stderr = String::from_utf8_lossy(&run.stderr);
    println!("{stdout}");
    assert!(
        run.status.success(),
        "the page's checks failed:\n{stdout}\n{stderr}\n(screenshots in {})",
        shots.display()
    );
    // Kept when it fails, for looking at.
    let _ = std::fs::remove_dir_all(&out);
}
