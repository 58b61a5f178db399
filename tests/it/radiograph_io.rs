//! TIFF reading: 8-bit, 16-bit, 32-bit float with deflate, multi-page stacks and numbered
//! frame directories (natural order), round-tripped through the writers.

use lbdem::io::tiff::{read_frames, read_pages, write_f32, write_u8, write_u16, write_u16_stack};
use ndarray::Array2;

#[test]
fn every_supported_layout_round_trips() {
    let d = tempfile::tempdir().unwrap();
    let p = d.path();
    let a16 = Array2::from_shape_fn((5, 7), |(r, c)| (r * 1000 + c) as u16);
    let a8 = Array2::from_shape_fn((5, 7), |(r, c)| (r * 10 + c) as u8);
    let mut af = Array2::from_shape_fn((5, 7), |(r, c)| r as f64 * 0.25 - c as f64);
    af[[2, 3]] = f64::NAN;
    write_u16(&p.join("a.tif"), a16.view()).unwrap();
    write_u8(&p.join("b.tif"), a8.view()).unwrap();
    write_f32(&p.join("c.tif"), af.view()).unwrap();
    assert_eq!(read_pages(&p.join("a.tif")).unwrap()[0].data, a16.mapv(f64::from));
    assert_eq!(read_pages(&p.join("b.tif")).unwrap()[0].bits, 8);
    let c = &read_pages(&p.join("c.tif")).unwrap()[0].data;
    assert!(c[[2, 3]].is_nan() && c[[4, 6]] == af[[4, 6]]);

    let b16 = a16.mapv(|v| v + 1);
    write_u16_stack(&p.join("stack.tif"), &[a16.view(), b16.view()]).unwrap();
    let s = read_pages(&p.join("stack.tif")).unwrap();
    assert_eq!(s.len(), 2);
    assert!(s[1].label.ends_with("#1") && s[1].data == b16.mapv(f64::from));

    let dir = p.join("frames");
    std::fs::create_dir(&dir).unwrap();
    for k in [10u16, 2, 1] {
        write_u16(&dir.join(format!("f_{k}.tif")), a16.mapv(|v| v + k).view()).unwrap();
    }
    let f = read_frames(&[dir]).unwrap();
    let firsts: Vec<f64> = f.iter().map(|x| x.data[[0, 0]]).collect();
    assert_eq!(firsts, vec![1.0, 2.0, 10.0], "numbered frames in natural order");
}
