//! COLMAP's blobs, decoded and encoded in one place: keypoints (float32 rows), matches and
//! inliers (uint32 pairs) and the float64 matrices and vectors of two-view geometries, all
//! little-endian and row-major as COLMAP writes them. Decoders check every size against what the
//! row promises, so a malformed blob is a one-line error, never a panic.

use anyhow::{anyhow, bail, Result};
use rusqlite::types::ValueRef;

/// A blob column's bytes; NULL is None. Other storage classes are an error, not a silent cast.
pub(crate) fn blob<'a>(value: ValueRef<'a>, what: &dyn Fn() -> String) -> Result<Option<&'a [u8]>> {
    match value {
        ValueRef::Blob(b) => Ok(Some(b)),
        ValueRef::Null => Ok(None),
        other => bail!("{}: expected a BLOB, found {:?}", what(), other.data_type()),
    }
}

/// Checks rows/cols/bytes of a row-major matrix blob and returns rows.
fn check_matrix(
    what: &dyn Fn() -> String,
    rows: i64,
    cols: i64,
    data: Option<&[u8]>,
    scalar_bytes: u64,
) -> Result<usize> {
    if rows < 0 || cols < 0 {
        bail!("{}: negative size {rows} x {cols}", what());
    }
    let expected = (rows as u64)
        .checked_mul(cols as u64)
        .and_then(|n| n.checked_mul(scalar_bytes))
        .ok_or_else(|| anyhow!("{}: size {rows} x {cols} overflows", what()))?;
    let actual = data.map_or(0, |d| d.len() as u64);
    if actual != expected {
        bail!(
            "{}: data has {actual} bytes, expected {expected} ({rows} rows x {cols} cols x {scalar_bytes} bytes)",
            what()
        );
    }
    Ok(rows as usize)
}

/// Keypoint (x, y) of a keypoints row: float32 rows x cols, cols in {2, 4, 6}.
pub fn decode_keypoints_xy(
    image_id: u32,
    rows: i64,
    cols: i64,
    data: Option<&[u8]>,
) -> Result<Vec<[f32; 2]>> {
    if ![2, 4, 6].contains(&cols) {
        bail!("keypoints of image {image_id}: {cols} columns, expected 2, 4 or 6");
    }
    let what = || format!("keypoints of image {image_id}");
    let n = check_matrix(&what, rows, cols, data, 4)?;
    let data = data.unwrap_or(&[]);
    let stride = cols as usize * 4;
    let f = |b: &[u8]| f32::from_le_bytes([b[0], b[1], b[2], b[3]]);
    Ok((0..n)
        .map(|i| {
            let r = &data[i * stride..];
            [f(&r[0..4]), f(&r[4..8])]
        })
        .collect())
}

/// A matches or two_view_geometries data blob: uint32 rows x 2. `what` names the row in errors.
pub fn decode_matches(
    what: &str,
    rows: i64,
    cols: i64,
    data: Option<&[u8]>,
) -> Result<Vec<[u32; 2]>> {
    if cols != 2 && !(rows == 0 && data.is_none_or(|d| d.is_empty())) {
        bail!("{what}: {cols} columns, expected 2");
    }
    let what_fn = || what.to_string();
    let n = check_matrix(&what_fn, rows, if rows == 0 { 0 } else { 2 }, data, 4)?;
    let data = data.unwrap_or(&[]);
    let u = |b: &[u8]| u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
    Ok((0..n)
        .map(|i| [u(&data[i * 8..i * 8 + 4]), u(&data[i * 8 + 4..i * 8 + 8])])
        .collect())
}

/// A fixed-size float64 blob (F/E/H: N = 9, qvec: 4, tvec: 3). NULL and zero-length blobs mean
/// "not set" (COLMAP reads both that way) and give None; any other size is an error. The values
/// are returned as stored: check `is_finite` before use.
pub fn decode_f64_array<const N: usize>(
    what: &str,
    data: Option<&[u8]>,
) -> Result<Option<[f64; N]>> {
    let data = match data {
        None => return Ok(None),
        Some([]) => return Ok(None),
        Some(d) => d,
    };
    if data.len() != N * 8 {
        bail!(
            "{what}: blob has {} bytes, expected {} ({N} float64)",
            data.len(),
            N * 8
        );
    }
    let mut out = [0.0; N];
    for (o, c) in out.iter_mut().zip(data.chunks_exact(8)) {
        *o = f64::from_le_bytes(c.try_into().expect("chunk of 8"));
    }
    Ok(Some(out))
}

/// A 3x3 row-major float64 matrix blob (F, E or H): 72 bytes, or None when not set.
pub fn decode_mat3(what: &str, data: Option<&[u8]>) -> Result<Option<[f64; 9]>> {
    decode_f64_array::<9>(what, data)
}

/// A stored F, E or H as something to compute with: None (taken as missing, the pose is then
/// estimated from the inliers) when a value is NaN or infinite or all are zero. The three are
/// defined only up to scale: one whose largest entry is beyond 2^±300 (where products of its
/// entries overflow or vanish) is scaled to a largest entry of ±1. NaN and infinite values made
/// nalgebra's unbounded iterations (rotation fitting, SVD) run forever.
pub fn usable_mat3(m: Option<[f64; 9]>) -> Option<[f64; 9]> {
    let m = m?;
    let largest = m
        .iter()
        .try_fold(0.0f64, |acc, x| x.is_finite().then(|| acc.max(x.abs())))?;
    const LIMIT: f64 = 2.037035976334486e90; // 2^300
    match largest {
        0.0 => None,
        l if (1.0 / LIMIT..=LIMIT).contains(&l) => Some(m),
        l => Some(m.map(|x| x / l)),
    }
}

/// A stored qvec (non-zero) or tvec: None when a value is NaN or infinite, or the qvec is zero.
pub fn usable_vec<const N: usize>(v: Option<[f64; N]>) -> Option<[f64; N]> {
    v.filter(|v| v.iter().all(|x| x.is_finite()) && (N != 4 || v.iter().any(|&x| x != 0.0)))
}

/// float32 values as a blob (keypoints: x, y[, a11, a12, a21, a22] per row).
pub fn encode_f32(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// float64 values as a blob (qvec, tvec, or a matrix already in row-major order).
pub fn encode_f64(values: &[f64]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// A 3x3 matrix (F, E or H) as COLMAP's row-major float64 blob.
pub fn encode_mat3(m: &nalgebra::Matrix3<f64>) -> Vec<u8> {
    encode_f64(m.transpose().as_slice())
}

/// Keypoint index pairs (matches, inliers) as a uint32 rows x 2 blob.
pub fn encode_pairs(pairs: &[[u32; 2]]) -> Vec<u8> {
    pairs
        .iter()
        .flat_map(|p| p.iter().flat_map(|v| v.to_le_bytes()))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn encoders_round_trip_through_the_decoders() {
        let m = nalgebra::Matrix3::new(1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0);
        let decoded = decode_mat3("F", Some(&encode_mat3(&m))).unwrap().unwrap();
        assert_eq!(decoded, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0]);
        let pairs = [[0, 7], [3, 1]];
        assert_eq!(
            decode_matches("pair", 2, 2, Some(&encode_pairs(&pairs))).unwrap(),
            pairs
        );
        let xy = [1.5f32, 2.5, 3.5, 4.5];
        assert_eq!(
            decode_keypoints_xy(1, 2, 2, Some(&encode_f32(&xy))).unwrap(),
            vec![[1.5, 2.5], [3.5, 4.5]]
        );
    }
}
