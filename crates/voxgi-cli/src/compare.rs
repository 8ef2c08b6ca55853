//! `voxgi compare`: FLIP and error metrics between an image and its reference.

use anyhow::{Context, Result};
use clap::Args;
use std::path::PathBuf;
use voxgi::compare::{self, Image};

#[derive(Args)]
pub struct CompareArgs {
    /// The reference image (.png or .exr).
    pub reference: PathBuf,
    /// The image to judge (same size and kind as the reference).
    pub test: PathBuf,
    /// Also write the per-pixel FLIP error as a PNG (magma colour map).
    #[arg(long, value_name = "FILE.png")]
    pub error_map: Option<PathBuf>,
}

pub fn run(args: &CompareArgs) -> Result<()> {
    let reference = Image::load(&args.reference)?;
    let test = Image::load(&args.test)?;
    let (c, map) = compare::compare_with_map(&reference, &test).with_context(|| {
        format!(
            "comparing {} with {}",
            args.test.display(),
            args.reference.display()
        )
    })?;
    if let Some(path) = &args.error_map {
        compare::save_error_map(path, reference.width, reference.height, &map)?;
    }
    println!(
        "{}",
        serde_json::json!({
            "flip_mean": c.flip_mean,
            "rmse": c.rmse,
            "rel_mse": c.rel_mse,
            "reference": args.reference.display().to_string(),
            "test": args.test.display().to_string(),
            "hdr": c.hdr,
        })
    );
    Ok(())
}
