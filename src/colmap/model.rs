//! COLMAP sparse models: their images and cameras as types, the folders of sub-models as
//! `colmap mapper` writes them (`sparse/0`, `sparse/1`, ...), the cameras of text models, and
//! writing text models (ground truth for `colmap model_aligner`). Reading a model's images,
//! text or binary, is [`super::sparse`]'s.

use anyhow::{ensure, Context, Result};
use nalgebra::{UnitQuaternion, Vector3};
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// One image of a COLMAP model (x_cam = rotation * X + translation).
#[derive(Clone, Debug)]
pub struct ModelImage {
    /// IMAGE_ID of the model (not necessarily the database's).
    pub image_id: u32,
    /// The image's camera in the model.
    pub camera_id: u32,
    /// Image name: what models and databases are matched by.
    pub name: String,
    /// World-to-camera rotation.
    pub rotation: UnitQuaternion<f64>,
    /// World-to-camera translation.
    pub translation: Vector3<f64>,
    /// Keypoints of the image on a 3D point of the model: the image's share of the bundle
    /// adjustment's residuals.
    pub observations: usize,
}

impl ModelImage {
    /// Camera centre -R^T t.
    pub fn centre(&self) -> Vector3<f64> {
        -(self.rotation.inverse() * self.translation)
    }
}

/// One camera of a COLMAP text model: its model's name and parameters as `cameras.txt` lists them.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelCamera {
    /// CAMERA_ID, as images.txt refers to it.
    pub camera_id: u32,
    /// COLMAP's model name, e.g. SIMPLE_RADIAL.
    pub model: String,
    /// Image width in pixels.
    pub width: u32,
    /// Image height in pixels.
    pub height: u32,
    /// The model's parameters in COLMAP's order (focal lengths, principal point, distortion).
    pub params: Vec<f64>,
}

/// Cameras of a COLMAP text model (`DIR/cameras.txt`): `CAMERA_ID MODEL WIDTH HEIGHT PARAMS[]`.
pub fn read_text_cameras(dir: &Path) -> Result<Vec<ModelCamera>> {
    let path = dir.join("cameras.txt");
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let mut out = Vec::new();
    for (no, line) in text.lines().enumerate() {
        let tok: Vec<&str> = line.split_whitespace().collect();
        if tok.is_empty() || tok[0].starts_with('#') {
            continue;
        }
        let at = || format!("{}:{}", path.display(), no + 1);
        ensure!(
            tok.len() >= 5,
            "{}: expected CAMERA_ID MODEL WIDTH HEIGHT PARAMS",
            at()
        );
        let params = tok[4..]
            .iter()
            .map(|t| t.parse::<f64>())
            .collect::<Result<_, _>>()
            .with_context(at)?;
        out.push(ModelCamera {
            camera_id: tok[0].parse().with_context(at)?,
            model: tok[1].to_string(),
            width: tok[2].parse().with_context(at)?,
            height: tok[3].parse().with_context(at)?,
            params,
        });
    }
    Ok(out)
}

/// Writes a COLMAP text model to `dir`: cameras.txt, images.txt with empty 2D-point lines and
/// an empty points3D.txt (poses only, as `colmap model_aligner` and `model_comparer` take).
pub fn write_text_model(dir: &Path, cameras: &[ModelCamera], images: &[ModelImage]) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    let mut cameras_txt = format!(
        "# Camera list with one line of data per camera:\n\
         #   CAMERA_ID, MODEL, WIDTH, HEIGHT, PARAMS[]\n\
         # Number of cameras: {}\n",
        cameras.len()
    );
    for c in cameras {
        write!(
            cameras_txt,
            "{} {} {} {}",
            c.camera_id, c.model, c.width, c.height
        )?;
        for p in &c.params {
            write!(cameras_txt, " {p}")?;
        }
        cameras_txt.push('\n');
    }
    let mut images_txt = format!(
        "# Image list with two lines of data per image:\n\
         #   IMAGE_ID, QW, QX, QY, QZ, TX, TY, TZ, CAMERA_ID, NAME\n\
         #   POINTS2D[] as (X, Y, POINT3D_ID)\n\
         # Number of images: {}, mean observations per image: 0\n",
        images.len()
    );
    for im in images {
        let (q, t) = (&im.rotation, im.translation);
        writeln!(
            images_txt,
            "{} {} {} {} {} {} {} {} {} {}\n",
            im.image_id, q.w, q.i, q.j, q.k, t.x, t.y, t.z, im.camera_id, im.name
        )?;
    }
    let points = "# 3D point list with one line of data per point:\n\
                  #   POINT3D_ID, X, Y, Z, R, G, B, ERROR, TRACK[] as (IMAGE_ID, POINT2D_IDX)\n\
                  # Number of points: 0, mean track length: 0\n";
    for (name, text) in [
        ("cameras.txt", cameras_txt.as_str()),
        ("images.txt", images_txt.as_str()),
        ("points3D.txt", points),
    ] {
        let path = dir.join(name);
        std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))?;
    }
    Ok(())
}

/// The model folders under `dir`: `dir` itself when it holds a model, else its sub-folders that
/// do, in name order (COLMAP numbers them 0, 1, ...; the first is the largest), then the models
/// of its sub-folders that are mapper outputs themselves: a second run on the images the first
/// left out, written into the first's folder (`sparse2/left`, README), belongs to the same run.
pub fn model_dirs(dir: &Path) -> Result<Vec<PathBuf>> {
    let is_model = |d: &Path| d.join("images.bin").is_file() || d.join("images.txt").is_file();
    if is_model(dir) {
        return Ok(vec![dir.to_path_buf()]);
    }
    let (models, others): (Vec<PathBuf>, Vec<PathBuf>) =
        sub_folders(dir)?.into_iter().partition(|p| is_model(p));
    let mut dirs = models;
    for other in others {
        dirs.extend(sub_folders(&other)?.into_iter().filter(|p| is_model(p)));
    }
    Ok(dirs)
}

/// The folders in `dir`, numbered ones first in their order, then the rest by name.
fn sub_folders(dir: &Path) -> Result<Vec<PathBuf>> {
    let entries = std::fs::read_dir(dir)
        .with_context(|| format!("cannot read model folder {}", dir.display()))?;
    let mut dirs: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_dir())
        .collect();
    dirs.sort_by_key(|p| {
        let name = p
            .file_name()
            .unwrap_or_default()
            .to_string_lossy()
            .to_string();
        (name.parse::<u64>().unwrap_or(u64::MAX), name)
    });
    Ok(dirs)
}
