//! Camera models from COLMAP's `cameras.params`, and keypoint undistortion to normalised image
//! coordinates (through OpenCV's `undistortPoints`).
//!
//! Relative poses and every geometric prior work on normalised coordinates, so each COLMAP model
//! is mapped to a calibration matrix K and OpenCV distortion coefficients (k1, k2, p1, p2[, k3..k6]),
//! which have the same meaning as COLMAP's for the supported models.

use crate::colmap::database::Camera;
use crate::colmap::ids::camera_model_name;
use anyhow::{bail, Result};
use nalgebra::Matrix3;
use opencv::core::{Mat, Point2d, Vector};

/// One COLMAP camera as K plus OpenCV distortion coefficients.
#[derive(Clone, Debug, PartialEq)]
pub struct CameraModel {
    pub camera_id: u32,
    pub fx: f64,
    pub fy: f64,
    pub cx: f64,
    pub cy: f64,
    /// OpenCV order: k1, k2, p1, p2, k3, k4, k5, k6 (zeros where the model has none).
    pub distortion: [f64; 8],
    pub width: u32,
    pub height: u32,
    /// False when COLMAP only guessed the focal length (1.2 × max(width, height)).
    pub prior_focal_length: bool,
}

impl CameraModel {
    /// Maps SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV and FULL_OPENCV; the fisheye
    /// and FOV models have no OpenCV `undistortPoints` equivalent and are refused.
    pub fn from_colmap(c: &Camera) -> Result<CameraModel> {
        let p = &c.params;
        let mut d = [0.0; 8];
        let (fx, fy, cx, cy) = match c.model_id {
            0 => (p[0], p[0], p[1], p[2]),
            1 => (p[0], p[1], p[2], p[3]),
            2 => {
                d[0] = p[3];
                (p[0], p[0], p[1], p[2])
            }
            3 => {
                d[..2].copy_from_slice(&p[3..5]);
                (p[0], p[0], p[1], p[2])
            }
            4 => {
                d[..4].copy_from_slice(&p[4..8]);
                (p[0], p[1], p[2], p[3])
            }
            6 => {
                d.copy_from_slice(&p[4..12]);
                (p[0], p[1], p[2], p[3])
            }
            m => bail!(
                "camera {}: model {} is not supported by the geometric priors \
                 (SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL, RADIAL, OPENCV, FULL_OPENCV are)",
                c.camera_id,
                camera_model_name(m).unwrap_or("unknown")
            ),
        };
        if !(fx > 0.0 && fy > 0.0) {
            bail!("camera {}: focal length must be positive", c.camera_id);
        }
        Ok(CameraModel {
            camera_id: c.camera_id,
            fx,
            fy,
            cx,
            cy,
            distortion: d,
            width: c.width,
            height: c.height,
            prior_focal_length: c.prior_focal_length,
        })
    }

    pub fn k(&self) -> Matrix3<f64> {
        Matrix3::new(self.fx, 0.0, self.cx, 0.0, self.fy, self.cy, 0.0, 0.0, 1.0)
    }

    /// Mean focal length in pixels, to turn pixel thresholds into normalised ones.
    pub fn focal(&self) -> f64 {
        0.5 * (self.fx + self.fy)
    }

    /// The same camera with focal length `f` (aspect ratio kept).
    pub fn with_focal(&self, f: f64) -> CameraModel {
        let aspect = self.fy / self.fx;
        CameraModel {
            fx: f,
            fy: f * aspect,
            ..self.clone()
        }
    }

    /// Keypoints (pixels) to undistorted normalised coordinates (x/z, y/z in the camera frame).
    pub fn normalise(&self, points: &[[f32; 2]]) -> Result<Vec<[f64; 2]>> {
        if points.is_empty() {
            return Ok(Vec::new());
        }
        let src: Vector<Point2d> = points
            .iter()
            .map(|p| Point2d::new(p[0] as f64, p[1] as f64))
            .collect();
        let k = Mat::from_slice_2d(&[
            [self.fx, 0.0, self.cx],
            [0.0, self.fy, self.cy],
            [0.0, 0.0, 1.0],
        ])?;
        let d = Mat::from_slice(&self.distortion)?;
        let mut dst: Vector<Point2d> = Vector::new();
        opencv::calib3d::undistort_points_def(&src, &mut dst, &k, &d)?;
        Ok(dst.iter().map(|p| [p.x, p.y]).collect())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn camera(model_id: i32, params: Vec<f64>) -> Camera {
        Camera {
            camera_id: 7,
            model_id,
            width: 640,
            height: 480,
            params,
            prior_focal_length: true,
        }
    }

    /// Distorts a normalised point with the Brown model, as COLMAP and OpenCV both define it.
    fn distort(d: &[f64; 8], x: f64, y: f64) -> (f64, f64) {
        let r2 = x * x + y * y;
        let radial = 1.0 + d[0] * r2 + d[1] * r2 * r2 + d[4] * r2 * r2 * r2;
        let xd = x * radial + 2.0 * d[2] * x * y + d[3] * (r2 + 2.0 * x * x);
        let yd = y * radial + d[2] * (r2 + 2.0 * y * y) + 2.0 * d[3] * x * y;
        (xd, yd)
    }

    #[test]
    fn undistortion_inverts_each_model() {
        let models = [
            camera(0, vec![500.0, 320.0, 240.0]),
            camera(1, vec![500.0, 520.0, 321.0, 239.0]),
            camera(2, vec![500.0, 320.0, 240.0, -0.12]),
            camera(3, vec![500.0, 320.0, 240.0, -0.1, 0.03]),
            camera(
                4,
                vec![500.0, 510.0, 320.0, 240.0, -0.1, 0.02, 0.001, -0.002],
            ),
        ];
        let truth = [[0.1, -0.2], [-0.3, 0.25], [0.0, 0.0], [0.4, 0.3]];
        for c in &models {
            let m = CameraModel::from_colmap(c).unwrap();
            let pixels: Vec<[f32; 2]> = truth
                .iter()
                .map(|&[x, y]| {
                    let (xd, yd) = distort(&m.distortion, x, y);
                    [(m.fx * xd + m.cx) as f32, (m.fy * yd + m.cy) as f32]
                })
                .collect();
            let back = m.normalise(&pixels).unwrap();
            for (b, t) in back.iter().zip(&truth) {
                assert!(
                    (b[0] - t[0]).abs() < 1e-5 && (b[1] - t[1]).abs() < 1e-5,
                    "model {}: {b:?} != {t:?}",
                    c.model_id
                );
            }
        }
    }

    #[test]
    fn unsupported_model_is_one_line_error() {
        let e = CameraModel::from_colmap(&camera(5, vec![0.0; 8])).unwrap_err();
        let msg = e.to_string();
        assert!(
            msg.contains("OPENCV_FISHEYE") && !msg.contains('\n'),
            "{msg}"
        );
    }
}
