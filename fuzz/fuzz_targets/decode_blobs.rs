//! The database blob decoders on arbitrary rows/cols/bytes: each returns a value or an error,
//! never panics, and a success has exactly the size rows/cols promised.
#![no_main]

use libfuzzer_sys::fuzz_target;
use vgsel_colmap::colmap::database::{decode_f64_array, decode_keypoints_xy, decode_mat3, decode_matches};

fuzz_target!(|input: &[u8]| {
    if input.len() < 3 {
        return;
    }
    // Byte 0 picks small or arbitrary sizes: small ones often agree with the data, so the
    // decoding itself runs, not only the size check.
    let (rows, cols, data) = if input[0] & 1 == 0 {
        (i64::from(input[1]), i64::from(input[2] % 8), &input[3..])
    } else if input.len() >= 17 {
        let rows = i64::from_le_bytes(input[1..9].try_into().unwrap());
        let cols = i64::from_le_bytes(input[9..17].try_into().unwrap());
        (rows, cols, &input[17..])
    } else {
        return;
    };
    let data = if input[0] & 2 == 0 { Some(data) } else { None };
    let len = data.map_or(0, <[u8]>::len);

    if let Ok(xy) = decode_keypoints_xy(7, rows, cols, data) {
        assert_eq!(xy.len() as i64, rows);
        assert_eq!(len as i64, rows * cols * 4);
    }
    if let Ok(m) = decode_matches("fuzz", rows, cols, data) {
        assert_eq!(m.len() as i64, rows);
        assert_eq!(len, m.len() * 8);
    }
    if let Ok(Some(_)) = decode_mat3("fuzz", data) {
        assert_eq!(len, 72);
    }
    if let Ok(Some(_)) = decode_f64_array::<4>("fuzz", data) {
        assert_eq!(len, 32);
    }
    for r in [decode_keypoints_xy(7, rows, cols, data).err(), decode_matches("fuzz", rows, cols, data).err()]
        .into_iter()
        .flatten()
    {
        assert!(!r.to_string().contains('\n'));
    }
});
