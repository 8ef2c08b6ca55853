//! Times the attribute estimation a point sequence runs on every frame (`PointsAhead::new`:
//! the neighbour search, normals, regions, radii and the surface spread) on a random subset
//! of a point file's points (or a mesh's vertices), several runs, and prints the median of
//! each step and a checksum of the neighbours found (equal wherever the same neighbours are
//! found).
//!
//!   cargo run --release -p voxgi-scene --example estimate_points -- \
//!       ../shared/scenes/pointcloud_pcl_office1/office1_xyzrgb.ply --points 100000
//!
//! Options: `--points N` (default all the input's), `--runs N` (default 5).

use std::time::Duration;
use voxgi_scene::PointCloud;
use voxgi_scene::prepare::PointsAhead;

fn main() {
    if let Err(e) = run() {
        eprintln!("estimate_points: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), String> {
    let mut args = std::env::args().skip(1);
    let input = args
        .next()
        .ok_or("usage: estimate_points INPUT [--points N] [--runs N]")?;
    let (mut count, mut runs) = (None, 5usize);
    while let Some(flag) = args.next() {
        let value = args.next().ok_or(format!("{flag} needs a value"))?;
        let bad = || format!("{flag} {value}: not a number");
        match flag.as_str() {
            "--points" => count = Some(value.parse::<usize>().map_err(|_| bad())?),
            "--runs" => runs = value.parse().map_err(|_| bad())?,
            _ => return Err(format!("unknown option {flag}")),
        }
    }
    if runs == 0 {
        return Err("--runs must be at least 1".into());
    }
    let mut scene =
        voxgi_scene::io::load(std::path::Path::new(&input)).map_err(|e| e.to_string())?;
    if scene.point_clouds.is_empty() {
        scene = voxgi_scene::pointcloud::mesh_vertices(&scene);
    }
    let mut positions: Vec<_> = scene
        .point_clouds
        .iter()
        .flat_map(|pc| {
            pc.positions
                .iter()
                .map(|&p| pc.transform.transform_point3(p))
        })
        .collect();
    if positions.is_empty() {
        return Err(format!("{input}: no points"));
    }
    // A random subset (a partial Fisher-Yates shuffle, a fixed seed): a sensor's new scan.
    let n = count.unwrap_or(positions.len()).min(positions.len());
    let mut state = 0x2545_f491_4f6c_dd1du64;
    for i in 0..n {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        let j = i + (state % (positions.len() - i) as u64) as usize;
        positions.swap(i, j);
    }
    positions.truncate(n);
    let mut steps: [Vec<Duration>; 6] = Default::default();
    let mut ahead = PointsAhead::default();
    for _ in 0..runs {
        let cloud = PointCloud {
            positions: positions.clone(),
            ..Default::default()
        };
        let t = std::time::Instant::now();
        ahead = PointsAhead::new(cloud);
        let total = t.elapsed();
        let timing = ahead.timing();
        for (s, d) in steps.iter_mut().zip([
            timing.neighbours,
            timing.normals,
            timing.regions,
            timing.radii,
            timing.spread,
            total,
        ]) {
            s.push(d);
        }
    }
    // Every run finds the same neighbours: the last run's are summed.
    let nb = ahead.neighbours();
    let checksum = (0..n).fold(0xcbf2_9ce4_8422_2325u64, |h, i| {
        nb.of(i, nb.k())
            .iter()
            .fold(h, |h, &j| (h ^ j as u64).wrapping_mul(0x100_0000_01b3))
    });
    let median = |v: &mut Vec<Duration>| {
        v.sort();
        v[v.len() / 2].as_secs_f64() * 1e3
    };
    let threads = std::thread::available_parallelism().map_or(1, |t| t.get());
    println!("{n} points, {runs} runs, {threads} threads; median ms:");
    for (name, s) in [
        "neighbours",
        "normals",
        "regions",
        "radii",
        "spread",
        "total",
    ]
    .iter()
    .zip(steps.iter_mut())
    {
        println!("  {name:<11} {:9.2}", median(s));
    }
    println!("neighbours checksum {checksum:016x}");
    Ok(())
}
