//! `tidepool render ocean --maps DIR`: tileable maps of a periodic sea patch for game engines
//! (height, displacement, normals, foam), one set or a numbered time series.
//!
//! Every flag is checked before the folder is created or a file written; each file is written
//! atomically (an interrupted series leaves whole files of the frames already done).

use std::path::Path;
use std::time::Instant;

use crate::SeaParams;
use crate::output::units::human_bytes;
use crate::sim::patch::{PatchMaps, PatchSea};

use super::stats::Stats;
use crate::cli::args::ocean::{MapFormat, RenderOcean};
use crate::cli::error::{Error, Result};
use crate::cli::files;
use crate::cli::progress::Progress;

/// The side of the maps without `--size`.
pub const DEFAULT_MAP_SIDE: usize = 1024;
/// At most this many texels over all frames (1000 frames of 1024x1024, about 28 GB of files).
pub const MAX_SERIES_TEXELS: u64 = 1 << 30;

/// Refuses `--out -` with `--maps`.
pub const MAPS_TO_STDOUT: &str = "maps are files in a folder and cannot go to standard output; drop --out - or --maps";

/// Checks the folder: one that exists, or nothing yet (it will be created).
pub fn check_folder(path: &Path) -> Result<()> {
    if path.exists() && !path.is_dir() {
        return Err(Error::arg(
            "--maps",
            format!("'{}' is a file; maps go into a folder (it is created if missing)", path.display()),
        ));
    }
    Ok(())
}

/// Writes the maps of `params` (already checked, loop included) into `dir`.
pub fn write(args: &RenderOcean, dir: &Path, params: SeaParams) -> Result<()> {
    match args.output.out.as_deref() {
        Some(out) if out.as_os_str() == "-" => return Err(Error::arg("--maps", MAPS_TO_STDOUT)),
        Some(out) => {
            return Err(Error::arg(
                "--maps",
                format!("maps replace the picture; drop --out {} or --maps", out.display()),
            ));
        }
        None => {}
    }
    if args.output.heightmap.is_some() {
        return Err(Error::arg("--heightmap", "--maps writes height.npy and height.png already; drop --heightmap"));
    }
    if args.output.format.is_some() {
        return Err(Error::arg(
            "--format",
            "maps are .npy, .png (and with --map-format exr, .exr) files; drop --format",
        ));
    }
    check_folder(dir)?;
    let n = match args.output.size {
        Some(size) => PatchSea::check_map_size(size.width() as usize, size.height() as usize)
            .map_err(|e| Error::arg("--size", e.to_string()))?,
        None => DEFAULT_MAP_SIDE,
    };
    let extent = args.extent.unwrap_or_else(|| PatchSea::default_extent_m(&params));
    PatchSea::check(n, extent)
        .map_err(|e| Error::arg(if e.what() == "map size" { "--size" } else { "--extent" }, e.to_string()))?;
    let frames = args.animation.frames.unwrap_or(1);
    let texels = u64::from(frames) * (n * n) as u64;
    if texels > MAX_SERIES_TEXELS {
        return Err(Error::arg(
            "--frames",
            format!(
                "{frames} frames of {n}x{n} maps are {texels} texels, over the {MAX_SERIES_TEXELS} tidepool writes at once; \
                 give fewer frames or a smaller --size"
            ),
        ));
    }
    let mut patch = PatchSea::new(params, n, extent).map_err(|e| Error::arg("--size", e.to_string()))?;
    std::fs::create_dir_all(dir).map_err(|e| Error::io("cannot create the folder", dir, e))?;
    let started = Instant::now();
    let mut progress = Progress::new("maps", u64::from(frames));
    let numbered = args.animation.frames.is_some();
    let exr = args.map_format.unwrap_or_default() == MapFormat::Exr;
    // A writer thread encodes and writes frame k while the next frame is computed (each file
    // is flushed to the device, which would otherwise leave the cores idle); at most two
    // frames wait, so memory stays bounded. The writer hands each written set back to be
    // computed over: at most four sets exist (two waiting, one written, one computed), and a
    // step does not fault in 32 MiB of fresh pages at 1024².
    let (send, receive) = std::sync::mpsc::sync_channel::<(u32, PatchMaps)>(2);
    let (hand_back, written) = std::sync::mpsc::channel::<PatchMaps>();
    let bytes = std::thread::scope(|scope| -> Result<usize> {
        let writer = scope.spawn(move || -> Result<usize> {
            let mut bytes = 0usize;
            for (k, maps) in receive {
                let frame = numbered.then_some(k);
                let exr_files = if exr { maps.exr_files(frame) } else { Vec::new() };
                for (name, file) in maps.files(frame).into_iter().chain(exr_files) {
                    bytes += file.len();
                    files::write_file(&dir.join(name), &file)?;
                }
                // The computing side may have finished: then the set is simply dropped.
                let _ = hand_back.send(maps);
            }
            Ok(bytes)
        });
        for k in 0..frames {
            // Frame k shows --time + k/fps, counted apart from --time so that a looping
            // series closes exactly: frame T·fps is frame 0.
            let mut maps = written.try_recv().unwrap_or_default();
            patch.maps_after(args.time, f64::from(k) / f64::from(args.animation.fps), &mut maps);
            if send.send((k, maps)).is_err() {
                break;
            }
            progress.advance(1);
        }
        drop(send);
        writer.join().map_err(|_| Error::Usage("the map writer stopped unexpectedly".into()))?
    })?;
    drop(progress);
    let mut stats = Stats::default();
    stats.record(
        "maps",
        started,
        format!("{frames} set(s) of {n}x{n} over {extent:.1} m into {}, {}", dir.display(), human_bytes(bytes as u64)),
    );
    stats.print_if(args.output.stats);
    Ok(())
}
