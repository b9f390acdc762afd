//! A whole COLMAP sparse model, text or binary: cameras, images with their 2D points and the
//! 3D point each lies on, and the 3D points' positions (tracks are the images' 2D points read
//! the other way round); or only the images' poses ([`read_images`]).

use super::ids::{camera_model_name, camera_model_num_params};
use super::model::{read_text_cameras, ModelCamera, ModelImage};
use anyhow::{ensure, Context, Result};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One keypoint of a model image: its pixel position (COLMAP's convention, 0.5 the first
/// pixel's centre) and the 3D point it was triangulated into, if any.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Point2D {
    /// Pixel x, y.
    pub xy: [f64; 2],
    /// POINT3D_ID, `None` for COLMAP's -1.
    pub point3d_id: Option<u64>,
}

/// One registered image with its pose and its keypoints.
#[derive(Clone, Debug)]
pub struct SparseImage {
    /// Pose, camera and name (its `observations` count the `points2d` on a 3D point).
    pub image: ModelImage,
    /// Every 2D point of the image, in COLMAP's POINT2D_IDX order.
    pub points2d: Vec<Point2D>,
}

/// A COLMAP sparse model folder, read whole.
#[derive(Clone, Debug, Default)]
pub struct SparseModel {
    /// Cameras by CAMERA_ID order.
    pub cameras: Vec<ModelCamera>,
    /// Registered images in the file's order.
    pub images: Vec<SparseImage>,
    /// 3D point positions by POINT3D_ID.
    pub points: BTreeMap<u64, [f64; 3]>,
}

/// The images of the model in `dir` with their poses, `images.bin` if present, else
/// `images.txt` (without their 2D points: what scoring a model against a ground truth needs).
pub fn read_images(dir: &Path) -> Result<Vec<ModelImage>> {
    let images = if dir.join("images.bin").is_file() {
        read_binary_images(dir)?
    } else {
        read_text_images(dir)?
    };
    Ok(images.into_iter().map(|i| i.image).collect())
}

/// Reads the model in `dir`: `cameras`, `images` and `points3D`, each `.bin` if present, else
/// `.txt`.
pub fn read_sparse_model(dir: &Path) -> Result<SparseModel> {
    let binary = dir.join("images.bin").is_file();
    let model = if binary {
        SparseModel {
            cameras: read_binary_cameras(dir)?,
            images: read_binary_images(dir)?,
            points: read_binary_points(dir)?,
        }
    } else {
        SparseModel {
            cameras: read_text_cameras(dir)?,
            images: read_text_images(dir)?,
            points: read_text_points(dir)?,
        }
    };
    Ok(model)
}

/// A little-endian cursor over a binary model file, whose errors name the file and offset.
struct Reader {
    bytes: Vec<u8>,
    at: usize,
    path: PathBuf,
}

impl Reader {
    /// The whole file at `path`, from its first byte.
    fn open(path: &Path) -> Result<Reader> {
        let bytes = std::fs::read(path).with_context(|| format!("reading {}", path.display()))?;
        Ok(Reader {
            bytes,
            at: 0,
            path: path.to_path_buf(),
        })
    }

    fn take(&mut self, n: usize) -> Result<&[u8]> {
        ensure!(
            self.at + n <= self.bytes.len(),
            "{}: truncated at byte {}",
            self.path.display(),
            self.at
        );
        self.at += n;
        Ok(&self.bytes[self.at - n..self.at])
    }
    fn skip(&mut self, n: usize) -> Result<()> {
        self.take(n).map(|_| ())
    }
    fn u32(&mut self) -> Result<u32> {
        Ok(u32::from_le_bytes(
            self.take(4)?.try_into().expect("4 bytes"),
        ))
    }
    fn u64(&mut self) -> Result<u64> {
        Ok(u64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
    fn f64(&mut self) -> Result<f64> {
        Ok(f64::from_le_bytes(
            self.take(8)?.try_into().expect("8 bytes"),
        ))
    }
    fn name(&mut self) -> Result<String> {
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

/// `cameras.bin`: u64 count, then per camera u32 id, i32 model, u64 width, u64 height and the
/// model's f64 parameters.
fn read_binary_cameras(dir: &Path) -> Result<Vec<ModelCamera>> {
    let mut r = Reader::open(&dir.join("cameras.bin"))?;
    let mut out = Vec::new();
    for _ in 0..r.u64()? {
        let camera_id = r.u32()?;
        let model_id = r.u32()? as i32;
        let (width, height) = (r.u64()? as u32, r.u64()? as u32);
        let n = camera_model_num_params(model_id)
            .with_context(|| format!("{}: unknown camera model {model_id}", r.path.display()))?;
        let params = (0..n).map(|_| r.f64()).collect::<Result<Vec<_>>>()?;
        let model = camera_model_name(model_id).unwrap_or("UNKNOWN");
        out.push(ModelCamera {
            camera_id,
            model: model.to_string(),
            width,
            height,
            params,
        });
    }
    Ok(out)
}

fn pose(q: [f64; 4], t: [f64; 3]) -> (UnitQuaternion<f64>, Vector3<f64>) {
    let rotation = UnitQuaternion::from_quaternion(Quaternion::new(q[0], q[1], q[2], q[3]));
    (rotation, Vector3::new(t[0], t[1], t[2]))
}

fn sparse_image(
    head: (u32, u32, String),
    q: [f64; 4],
    t: [f64; 3],
    points2d: Vec<Point2D>,
) -> SparseImage {
    let (rotation, translation) = pose(q, t);
    let observations = points2d.iter().filter(|p| p.point3d_id.is_some()).count();
    SparseImage {
        image: ModelImage {
            image_id: head.0,
            camera_id: head.1,
            name: head.2,
            rotation,
            translation,
            observations,
        },
        points2d,
    }
}

/// `images.bin`: per image u32 id, 4 f64 qvec, 3 f64 tvec, u32 camera id, a NUL-terminated
/// name, u64 point count and that many (f64 x, f64 y, i64 point3D id).
fn read_binary_images(dir: &Path) -> Result<Vec<SparseImage>> {
    let mut r = Reader::open(&dir.join("images.bin"))?;
    let mut out = Vec::new();
    for _ in 0..r.u64()? {
        let image_id = r.u32()?;
        let q = [r.f64()?, r.f64()?, r.f64()?, r.f64()?];
        let t = [r.f64()?, r.f64()?, r.f64()?];
        let camera_id = r.u32()?;
        let name = r.name()?;
        let n = r.u64()?;
        let mut points2d = Vec::new();
        for _ in 0..n {
            let xy = [r.f64()?, r.f64()?];
            let id = r.u64()?;
            let point3d_id = (id != u64::MAX).then_some(id);
            points2d.push(Point2D { xy, point3d_id });
        }
        out.push(sparse_image((image_id, camera_id, name), q, t, points2d));
    }
    Ok(out)
}

/// `points3D.bin`: per point u64 id, 3 f64 xyz, 3 u8 colour, f64 error, u64 track length and
/// that many (u32 image id, u32 point2D index).
fn read_binary_points(dir: &Path) -> Result<BTreeMap<u64, [f64; 3]>> {
    let mut r = Reader::open(&dir.join("points3D.bin"))?;
    let mut out = BTreeMap::new();
    for _ in 0..r.u64()? {
        let id = r.u64()?;
        let xyz = [r.f64()?, r.f64()?, r.f64()?];
        r.skip(3 + 8)?;
        let track = r.u64()? as usize;
        r.skip(track.checked_mul(8).context("track length overflows")?)?;
        out.insert(id, xyz);
    }
    Ok(out)
}

fn text_lines(path: &Path) -> Result<Vec<(usize, String)>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    Ok(text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.starts_with('#'))
        .map(|(k, l)| (k + 1, l.to_string()))
        .collect())
}

fn numbers(path: &Path, no: usize, tokens: &[&str]) -> Result<Vec<f64>> {
    tokens
        .iter()
        .map(|t| t.parse::<f64>())
        .collect::<Result<_, _>>()
        .with_context(|| format!("{}:{no}: bad number", path.display()))
}

/// `images.txt`: a pose line `IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME`, then a line of
/// `X Y POINT3D_ID` triples (possibly empty).
fn read_text_images(dir: &Path) -> Result<Vec<SparseImage>> {
    let path = dir.join("images.txt");
    let lines = text_lines(&path)?;
    let mut out = Vec::new();
    let mut k = 0;
    while k < lines.len() {
        let (no, line) = &lines[k];
        k += 1;
        let tok: Vec<&str> = line.split_whitespace().collect();
        if tok.is_empty() {
            continue;
        }
        let at = || format!("{}:{no}", path.display());
        ensure!(
            tok.len() >= 10,
            "{}: expected IMAGE_ID QW QX QY QZ TX TY TZ CAMERA_ID NAME",
            at()
        );
        let v = numbers(&path, *no, &tok[1..8])?;
        let head = (
            tok[0].parse().with_context(at)?,
            tok[8].parse().with_context(at)?,
            tok[9..].join(" "),
        );
        let points = lines.get(k).map_or("", |l| l.1.as_str());
        k += 1;
        let points2d =
            text_points2d(points).with_context(|| format!("{}:{}", path.display(), no + 1))?;
        out.push(sparse_image(
            head,
            [v[0], v[1], v[2], v[3]],
            [v[4], v[5], v[6]],
            points2d,
        ));
    }
    Ok(out)
}

fn text_points2d(line: &str) -> Result<Vec<Point2D>> {
    let tok: Vec<&str> = line.split_whitespace().collect();
    ensure!(
        tok.len().is_multiple_of(3),
        "expected X Y POINT3D_ID triples"
    );
    tok.chunks(3)
        .map(|c| {
            let id: i64 = c[2].parse().context("bad POINT3D_ID")?;
            Ok(Point2D {
                xy: [c[0].parse()?, c[1].parse()?],
                point3d_id: u64::try_from(id).ok(),
            })
        })
        .collect()
}

/// `points3D.txt`: `POINT3D_ID X Y Z R G B ERROR TRACK[]`.
fn read_text_points(dir: &Path) -> Result<BTreeMap<u64, [f64; 3]>> {
    let path = dir.join("points3D.txt");
    let mut out = BTreeMap::new();
    for (no, line) in text_lines(&path)? {
        let tok: Vec<&str> = line.split_whitespace().collect();
        if tok.is_empty() {
            continue;
        }
        ensure!(
            tok.len() >= 8,
            "{}:{no}: expected POINT3D_ID X Y Z R G B ERROR",
            path.display()
        );
        let id = tok[0]
            .parse()
            .with_context(|| format!("{}:{no}: bad POINT3D_ID", path.display()))?;
        let v = numbers(&path, no, &tok[1..4])?;
        out.insert(id, [v[0], v[1], v[2]]);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::model::{model_dirs, write_text_model};
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
        let images = read_images(dir.path()).unwrap();
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
        // Three 2D points, the second on no 3D point.
        let points = [([0.0, 0.0], 5), ([0.0, 0.0], u64::MAX), ([0.0, 0.0], 0)];
        let bin = one_image_bin(
            7,
            [1.0, 0.0, 0.0, 0.0, 1.0, 2.0, 3.0],
            2,
            "a b.png",
            &points,
        );
        std::fs::write(model.join("images.bin"), &bin).unwrap();
        assert_eq!(model_dirs(dir.path()).unwrap(), vec![model.clone()]);
        // A second mapper run written into the first's folder belongs to the run; a folder
        // deeper down does not, nor does an empty one.
        let (left, deeper) = (dir.path().join("left/0"), dir.path().join("left/x/0"));
        for d in [&left, &deeper, &dir.path().join("empty")] {
            std::fs::create_dir_all(d).unwrap();
        }
        std::fs::write(left.join("images.bin"), &bin).unwrap();
        std::fs::write(deeper.join("images.bin"), &bin).unwrap();
        let found = model_dirs(dir.path()).unwrap();
        assert_eq!(found, vec![model.clone(), left.clone()]);
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

    #[test]
    fn text_models_read_whole() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(
            d.join("cameras.txt"),
            "# c\n1 SIMPLE_RADIAL 480 360 400 240 180 0\n",
        )
        .unwrap();
        std::fs::write(
            d.join("images.txt"),
            "# i\n1 1 0 0 0 0 0 0 1 a.png\n10 20 5 30 40 -1\n2 1 0 0 0 1 0 0 1 b.png\n\n",
        )
        .unwrap();
        std::fs::write(
            d.join("points3D.txt"),
            "# p\n5 0.5 1 2 255 0 0 0.1 1 0 2 3\n",
        )
        .unwrap();
        let m = read_sparse_model(d).unwrap();
        assert_eq!(m.cameras[0].params, vec![400.0, 240.0, 180.0, 0.0]);
        assert_eq!(m.images.len(), 2);
        assert_eq!(m.images[0].points2d[0].point3d_id, Some(5));
        assert_eq!(m.images[0].points2d[1].point3d_id, None);
        assert_eq!(m.images[0].image.observations, 1);
        assert!(m.images[1].points2d.is_empty());
        assert_eq!(m.points[&5], [0.5, 1.0, 2.0]);
    }

    /// `images.bin` of one image: its id, qvec and tvec, camera, name and 2D points (x, y and
    /// point3D id; u64::MAX for none).
    fn one_image_bin(
        image_id: u32,
        pose: [f64; 7],
        camera_id: u32,
        name: &str,
        points: &[([f64; 2], u64)],
    ) -> Vec<u8> {
        let mut bin = 1u64.to_le_bytes().to_vec();
        bin.extend(image_id.to_le_bytes());
        pose.iter().for_each(|x| bin.extend(x.to_le_bytes()));
        bin.extend(camera_id.to_le_bytes());
        bin.extend(name.as_bytes());
        bin.push(0);
        bin.extend((points.len() as u64).to_le_bytes());
        for (xy, id) in points {
            xy.iter().for_each(|x| bin.extend(x.to_le_bytes()));
            bin.extend(id.to_le_bytes());
        }
        bin
    }

    #[test]
    fn binary_models_read_whole() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let mut cams = 1u64.to_le_bytes().to_vec();
        cams.extend(3u32.to_le_bytes());
        cams.extend(0i32.to_le_bytes());
        cams.extend(480u64.to_le_bytes());
        cams.extend(360u64.to_le_bytes());
        for x in [400.0f64, 240.0, 180.0] {
            cams.extend(x.to_le_bytes());
        }
        std::fs::write(d.join("cameras.bin"), cams).unwrap();
        let ims = one_image_bin(
            7,
            [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
            3,
            "a.png",
            &[([12.5, 7.5], 9)],
        );
        std::fs::write(d.join("images.bin"), ims).unwrap();
        let mut pts = 1u64.to_le_bytes().to_vec();
        pts.extend(9u64.to_le_bytes());
        for x in [1.0f64, 2.0, 3.0] {
            pts.extend(x.to_le_bytes());
        }
        pts.extend([1u8, 2, 3]);
        pts.extend(0.5f64.to_le_bytes());
        pts.extend(1u64.to_le_bytes());
        pts.extend([7u32.to_le_bytes(), 0u32.to_le_bytes()].concat());
        std::fs::write(d.join("points3D.bin"), pts).unwrap();
        let m = read_sparse_model(d).unwrap();
        assert_eq!(
            (m.cameras[0].camera_id, m.cameras[0].model.as_str()),
            (3, "SIMPLE_PINHOLE")
        );
        assert_eq!(
            m.images[0].points2d,
            vec![Point2D {
                xy: [12.5, 7.5],
                point3d_id: Some(9)
            }]
        );
        assert_eq!(m.points[&9], [1.0, 2.0, 3.0]);
    }
}
