//! Reading COLMAP sparse models (the images and their poses), text or binary, one model or a
//! folder of sub-models as `colmap mapper` writes them (`sparse/0`, `sparse/1`, ...); the
//! cameras of text models; writing text models (ground truth for `colmap model_aligner`).

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

/// Images of a COLMAP text model (`DIR/images.txt`): each image is a pose line
/// `IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME` followed by a (possibly empty) 2D-point line.
fn read_text_images(dir: &Path) -> Result<Vec<ModelImage>> {
    let path = dir.join("images.txt");
    let text =
        std::fs::read_to_string(&path).with_context(|| format!("reading {}", path.display()))?;
    let mut out = Vec::new();
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.starts_with('#'));
    while let Some((no, line)) = lines.next() {
        if line.trim().is_empty() {
            continue;
        }
        let tok: Vec<&str> = line.split_whitespace().collect();
        ensure!(
            tok.len() >= 10,
            "{}:{}: expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME",
            path.display(),
            no + 1
        );
        let num = |i: usize| -> Result<f64> {
            tok[i]
                .parse::<f64>()
                .with_context(|| format!("{}:{}: bad number {:?}", path.display(), no + 1, tok[i]))
        };
        let q = nalgebra::Quaternion::new(num(1)?, num(2)?, num(3)?, num(4)?);
        out.push(ModelImage {
            image_id: tok[0]
                .parse()
                .with_context(|| format!("{}:{}: bad IMAGE_ID", path.display(), no + 1))?,
            camera_id: tok[8]
                .parse()
                .with_context(|| format!("{}:{}: bad CAMERA_ID", path.display(), no + 1))?,
            name: tok[9..].join(" "),
            rotation: UnitQuaternion::from_quaternion(q),
            translation: Vector3::new(num(5)?, num(6)?, num(7)?),
            // The 2D-point line (may be empty): X Y POINT3D_ID triples, -1 for no point.
            observations: lines.next().map_or(0, |(_, points)| {
                points
                    .split_whitespace()
                    .skip(2)
                    .step_by(3)
                    .filter(|id| *id != "-1")
                    .count()
            }),
        });
    }
    Ok(out)
}

/// Images of one model folder: `images.bin` if present, else `images.txt`.
pub fn read_images(dir: &Path) -> Result<Vec<ModelImage>> {
    if dir.join("images.bin").is_file() {
        read_binary_images(dir)
    } else {
        read_text_images(dir)
    }
}

/// The model folders under `dir`: `dir` itself when it holds a model, else its sub-folders that
/// do, in name order (COLMAP numbers them 0, 1, ...; the first is the largest).
pub fn model_dirs(dir: &Path) -> Result<Vec<PathBuf>> {
    let is_model = |d: &Path| d.join("images.bin").is_file() || d.join("images.txt").is_file();
    if is_model(dir) {
        return Ok(vec![dir.to_path_buf()]);
    }
    let entries = std::fs::read_dir(dir)
        .with_context(|| format!("cannot read model folder {}", dir.display()))?;
    let mut dirs: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| is_model(p))
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

/// `images.bin`: u64 count, then per image u32 id, 4 f64 qvec, 3 f64 tvec, u32 camera id, a
/// NUL-terminated name, u64 point count and that many (f64 x, f64 y, i64 point3D id).
fn read_binary_images(dir: &Path) -> Result<Vec<ModelImage>> {
    let path = dir.join("images.bin");
    let bytes = std::fs::read(&path).with_context(|| format!("reading {}", path.display()))?;
    let mut r = Reader {
        bytes: &bytes,
        at: 0,
        path: &path,
    };
    let count = r.u64()?;
    let mut out = Vec::new();
    for _ in 0..count {
        let image_id = r.u32()?;
        let q = [r.f64()?, r.f64()?, r.f64()?, r.f64()?];
        let t = [r.f64()?, r.f64()?, r.f64()?];
        let camera_id = r.u32()?;
        let name = r.name()?;
        let points = r.u64()?;
        let mut observations = 0;
        for _ in 0..points {
            r.skip(16)?;
            // COLMAP's invalid point id is u64::MAX (-1 as i64).
            observations += usize::from(r.u64()? != u64::MAX);
        }
        out.push(ModelImage {
            image_id,
            camera_id,
            name,
            rotation: UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
                q[0], q[1], q[2], q[3],
            )),
            translation: Vector3::new(t[0], t[1], t[2]),
            observations,
        });
    }
    Ok(out)
}

/// A little-endian cursor over a binary model file, whose errors name the file and offset.
pub(super) struct Reader<'a> {
    pub(super) bytes: &'a [u8],
    pub(super) at: usize,
    pub(super) path: &'a Path,
}

impl Reader<'_> {
    pub(super) fn take(&mut self, n: usize) -> Result<&[u8]> {
        ensure!(
            self.at + n <= self.bytes.len(),
            "{}: truncated at byte {}",
            self.path.display(),
            self.at
        );
        self.at += n;
        Ok(&self.bytes[self.at - n..self.at])
    }
    pub(super) fn skip(&mut self, n: usize) -> Result<()> {
        self.take(n).map(|_| ())
    }
    pub(super) fn u32(&mut self) -> Result<u32> {
        Ok(u32::from_le_bytes(
            self.take(4)?.try_into().expect("4 bytes"),
        ))
    }
    pub(super) fn u64(&mut self) -> Result<u64> {
        Ok(u64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
    pub(super) fn f64(&mut self) -> Result<f64> {
        Ok(f64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
    pub(super) fn name(&mut self) -> Result<String> {
        let rest = &self.bytes[self.at..];
        let end = rest
            .iter()
            .position(|&b| b == 0)
            .with_context(|| format!("{}: unterminated name", self.path.display()))?;
        let name = String::from_utf8_lossy(&rest[..end]).into_owned();
        self.at += end + 1;
        Ok(name)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_text_model_with_empty_point_lines() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(
            dir.path().join("images.txt"),
            "# comment\n# Number of images: 2\n\
             1 1 0 0 0 1 2 3 1 a.jpg\n\
             10.5 20.5 -1 11.5 2.5 4 1.5 3.5 9\n\
             2 0 1 0 0 0 0 1 1 b c.jpg\n\n",
        )
        .unwrap();
        let images = read_text_images(dir.path()).unwrap();
        assert_eq!(images.len(), 2);
        assert_eq!(images[0].name, "a.jpg");
        assert_eq!(images[1].name, "b c.jpg");
        assert_eq!((images[0].observations, images[1].observations), (2, 0));
        assert!((images[0].centre() + Vector3::new(1.0, 2.0, 3.0)).norm() < 1e-12);
        assert!((images[1].centre() - Vector3::new(0.0, 0.0, 1.0)).norm() < 1e-12);
    }

    #[test]
    fn written_text_models_read_back() {
        let dir = tempfile::tempdir().unwrap();
        let camera = ModelCamera {
            camera_id: 3,
            model: "RADIAL".into(),
            width: 640,
            height: 480,
            params: vec![500.5, 320.0, 240.0, -0.1, 0.01],
        };
        let image = ModelImage {
            image_id: 7,
            camera_id: 3,
            name: "a b.jpg".into(),
            rotation: UnitQuaternion::from_euler_angles(0.1, -0.2, 0.3),
            translation: Vector3::new(1.0, -2.0, 0.5),
            observations: 0,
        };
        write_text_model(
            dir.path(),
            std::slice::from_ref(&camera),
            std::slice::from_ref(&image),
        )
        .unwrap();
        assert_eq!(read_text_cameras(dir.path()).unwrap(), vec![camera]);
        let back = read_images(dir.path()).unwrap();
        assert_eq!((back[0].image_id, back[0].camera_id), (7, 3));
        assert_eq!(back[0].name, image.name);
        assert!(back[0].rotation.angle_to(&image.rotation) < 1e-12);
        assert!((back[0].translation - image.translation).norm() < 1e-12);
    }

    #[test]
    fn binary_and_text_agree_and_sub_models_are_found() {
        let dir = tempfile::tempdir().unwrap();
        let model = dir.path().join("1");
        std::fs::create_dir_all(&model).unwrap();
        let mut bin = 1u64.to_le_bytes().to_vec();
        bin.extend(7u32.to_le_bytes());
        for x in [1.0f64, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0] {
            bin.extend(x.to_le_bytes());
        }
        bin.extend(2u32.to_le_bytes());
        bin.extend(b"a b.png\0");
        // Three 2D points, the second on no 3D point.
        bin.extend(3u64.to_le_bytes());
        for id in [5u64, u64::MAX, 0] {
            bin.extend([0u8; 16]);
            bin.extend(id.to_le_bytes());
        }
        std::fs::write(model.join("images.bin"), &bin).unwrap();
        assert_eq!(model_dirs(dir.path()).unwrap(), vec![model.clone()]);
        let images = read_images(&model).unwrap();
        assert_eq!(
            (
                images[0].image_id,
                images[0].camera_id,
                images[0].name.as_str()
            ),
            (7, 2, "a b.png")
        );
        assert_eq!(images[0].observations, 2);
        assert!((images[0].centre() + Vector3::new(1.0, 2.0, 3.0)).norm() < 1e-12);
        std::fs::write(model.join("images.bin"), &bin[..bin.len() - 1]).unwrap();
        assert!(read_images(&model)
            .unwrap_err()
            .to_string()
            .contains("truncated"));
    }
}
