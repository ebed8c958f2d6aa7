//! What a reference image shows: the scene file, camera, size and samples, written by
//! `reference` (and `merge`) beside the mean as `<name>.json`, so that `compare` can refuse a
//! reference of another camera instead of measuring against it.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context as _, Result};
use serde::{Deserialize, Serialize};

/// The record of one reference image.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReferenceRecord {
    /// The scene file's name (no folder).
    pub scene: String,
    /// The glTF camera index the image is seen from.
    pub camera: usize,
    pub width: u32,
    pub height: u32,
    /// Path-traced samples per pixel of the mean.
    pub spp: u32,
}

/// The record's path: `ref.exr` -> `ref.json`.
pub fn record_path(reference: &Path) -> PathBuf {
    reference.with_extension("json")
}

/// The file name of a scene path, as records store it.
pub fn scene_name(scene: &Path) -> String {
    scene.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default()
}

pub fn write_record(reference: &Path, record: &ReferenceRecord) -> Result<()> {
    let path = record_path(reference);
    std::fs::write(&path, serde_json::to_string_pretty(record)?).with_context(|| format!("{}: cannot write", path.display()))
}

/// The record beside `reference`, if there is one.
pub fn read_record(reference: &Path) -> Result<Option<ReferenceRecord>> {
    let path = record_path(reference);
    if !path.exists() {
        return Ok(None);
    }
    let text = std::fs::read_to_string(&path).with_context(|| format!("{}: cannot read", path.display()))?;
    let record = serde_json::from_str(&text).with_context(|| format!("{}: not a reference record", path.display()))?;
    Ok(Some(record))
}

/// Fails unless `reference` shows `scene` from `camera` and its record agrees with the image's
/// `size` (width, height); warns when it carries no record. Returns the record, if any.
pub fn check_reference(reference: &Path, scene: &Path, camera: usize, size: (u32, u32)) -> Result<Option<ReferenceRecord>> {
    let Some(record) = read_record(reference)? else {
        eprintln!(
            "warning: {}: no {} record says which camera it shows; make sure it is camera {camera} of {}",
            reference.display(),
            record_path(reference).display(),
            scene.display()
        );
        return Ok(None);
    };
    if record.scene != scene_name(scene) || record.camera != camera {
        bail!(
            "{}: a reference of camera {} of {}, but the run's last frame sees camera {camera} of {} (restir-pt reference {} --camera {camera})",
            reference.display(),
            record.camera,
            record.scene,
            scene_name(scene),
            scene.display()
        );
    }
    if (record.width, record.height) != size {
        bail!(
            "{}: {}x{} pixels, but its record says {}x{}: the image and its .json record do not belong together",
            reference.display(),
            size.0,
            size.1,
            record.width,
            record.height
        );
    }
    Ok(Some(record))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reference_record_round_trips_and_refuses_another_camera() {
        let dir = std::env::temp_dir().join(format!("restir-pt-record-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let reference = dir.join("ref.exr");
        let scene = Path::new("scenes/cornell.gltf");
        let record = ReferenceRecord {
            scene: "cornell.gltf".into(),
            camera: 2,
            width: 16,
            height: 8,
            spp: 32,
        };
        check_reference(&reference, scene, 5, (16, 8)).unwrap();
        write_record(&reference, &record).unwrap();
        assert_eq!(read_record(&reference).unwrap(), Some(record));
        check_reference(&reference, scene, 2, (16, 8)).unwrap();
        assert!(check_reference(&reference, scene, 2, (8, 8)).is_err(), "another size");
        let err = check_reference(&reference, scene, 3, (16, 8)).unwrap_err().to_string();
        assert!(err.contains("camera 2") && err.contains("camera 3"), "{err}");
        assert!(check_reference(&reference, Path::new("scenes/veach-door.gltf"), 2, (16, 8)).is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
