//! Minimal VTK XML writers (`.vti` image data, `.vtp` points, `.pvd` collections) that
//! ParaView opens. Arrays are stored as appended raw little-endian binary with UInt64
//! block headers: compact, exact, and simple enough not to need a dependency.

use crate::atomic::write_atomic_with;
use std::io::{self, Write};
use std::path::Path;

/// Values of one data array, borrowed from the caller.
#[derive(Clone, Copy, Debug)]
pub enum Values<'a> {
    F32(&'a [f32]),
    F64(&'a [f64]),
    I32(&'a [i32]),
}

impl Values<'_> {
    fn len(&self) -> usize {
        match self {
            Values::F32(v) => v.len(),
            Values::F64(v) => v.len(),
            Values::I32(v) => v.len(),
        }
    }
    fn type_name(&self) -> &'static str {
        match self {
            Values::F32(_) => "Float32",
            Values::F64(_) => "Float64",
            Values::I32(_) => "Int32",
        }
    }
    fn byte_len(&self) -> usize {
        self.len() * 4 * if matches!(self, Values::F64(_)) { 2 } else { 1 }
    }
    fn write_le(&self, w: &mut impl Write) -> io::Result<()> {
        match self {
            Values::F32(v) => v.iter().try_for_each(|x| w.write_all(&x.to_le_bytes())),
            Values::F64(v) => v.iter().try_for_each(|x| w.write_all(&x.to_le_bytes())),
            Values::I32(v) => v.iter().try_for_each(|x| w.write_all(&x.to_le_bytes())),
        }
    }
}

/// A named array with `components` values per point (1 scalar, 3 vector).
#[derive(Clone, Copy, Debug)]
pub struct Array<'a> {
    pub name: &'a str,
    pub components: usize,
    pub values: Values<'a>,
}

impl<'a> Array<'a> {
    pub fn scalar(name: &'a str, values: Values<'a>) -> Self {
        Self {
            name,
            components: 1,
            values,
        }
    }
    pub fn vector(name: &'a str, values: Values<'a>) -> Self {
        Self {
            name,
            components: 3,
            values,
        }
    }
}

fn check_len(a: &Array, n: usize) -> io::Result<()> {
    if a.values.len() != a.components * n {
        return Err(io::Error::new(
            io::ErrorKind::InvalidInput,
            format!(
                "VTK array '{}' has {} values, expected {} ({} points x {} components)",
                a.name,
                a.values.len(),
                a.components * n,
                n,
                a.components
            ),
        ));
    }
    Ok(())
}

/// Writes `<DataArray>` headers with running offsets; returns the arrays in order.
fn data_array_headers(w: &mut impl Write, arrays: &[Array], offset: &mut u64) -> io::Result<()> {
    for a in arrays {
        writeln!(
            w,
            r#"<DataArray type="{}" Name="{}" NumberOfComponents="{}" format="appended" offset="{}"/>"#,
            a.values.type_name(),
            a.name,
            a.components,
            offset
        )?;
        *offset += 8 + a.values.byte_len() as u64;
    }
    Ok(())
}

fn appended(w: &mut impl Write, arrays: &[&Array]) -> io::Result<()> {
    write!(w, "<AppendedData encoding=\"raw\">\n_")?;
    for a in arrays {
        w.write_all(&(a.values.byte_len() as u64).to_le_bytes())?;
        a.values.write_le(w)?;
    }
    writeln!(w, "\n</AppendedData>")
}

const HEADER: &str = r#"<?xml version="1.0"?>"#;

/// Uniform grid of `dims` points (x fastest) with `origin` and `spacing`, point data only.
pub fn write_vti(
    path: &Path,
    dims: [usize; 3],
    origin: [f64; 3],
    spacing: [f64; 3],
    point_data: &[Array],
) -> io::Result<()> {
    let n = dims.iter().product::<usize>();
    point_data.iter().try_for_each(|a| check_len(a, n))?;
    write_atomic_with(path, |w| {
        let ext = format!(
            "0 {} 0 {} 0 {}",
            dims[0].saturating_sub(1),
            dims[1].saturating_sub(1),
            dims[2].saturating_sub(1)
        );
        writeln!(w, "{HEADER}")?;
        writeln!(
            w,
            r#"<VTKFile type="ImageData" version="1.0" byte_order="LittleEndian" header_type="UInt64">"#
        )?;
        writeln!(
            w,
            r#"<ImageData WholeExtent="{ext}" Origin="{} {} {}" Spacing="{} {} {}">"#,
            origin[0], origin[1], origin[2], spacing[0], spacing[1], spacing[2]
        )?;
        writeln!(w, r#"<Piece Extent="{ext}">"#)?;
        writeln!(w, "<PointData>")?;
        let mut offset = 0;
        data_array_headers(w, point_data, &mut offset)?;
        writeln!(w, "</PointData>\n</Piece>\n</ImageData>")?;
        appended(w, &point_data.iter().collect::<Vec<_>>())?;
        writeln!(w, "</VTKFile>")
    })
}

/// Points (particles) with per-point data, e.g. radius, velocity, grain id.
pub fn write_vtp_points(path: &Path, positions: &[[f64; 3]], point_data: &[Array]) -> io::Result<()> {
    let n = positions.len();
    point_data.iter().try_for_each(|a| check_len(a, n))?;
    let flat: Vec<f64> = positions.iter().flatten().copied().collect();
    let pos = Array::vector("Points", Values::F64(&flat));
    let conn: Vec<i32> = (0..n as i32).collect();
    let offs: Vec<i32> = (1..=n as i32).collect();
    let conn_a = Array::scalar("connectivity", Values::I32(&conn));
    let offs_a = Array::scalar("offsets", Values::I32(&offs));
    write_atomic_with(path, |w| {
        writeln!(w, "{HEADER}")?;
        writeln!(
            w,
            r#"<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian" header_type="UInt64">"#
        )?;
        writeln!(w, r#"<PolyData><Piece NumberOfPoints="{n}" NumberOfVerts="{n}">"#)?;
        let mut offset = 0;
        writeln!(w, "<PointData>")?;
        data_array_headers(w, point_data, &mut offset)?;
        writeln!(w, "</PointData>\n<Points>")?;
        data_array_headers(w, std::slice::from_ref(&pos), &mut offset)?;
        writeln!(w, "</Points>\n<Verts>")?;
        data_array_headers(w, &[conn_a, offs_a], &mut offset)?;
        writeln!(w, "</Verts>\n</Piece></PolyData>")?;
        let mut all: Vec<&Array> = point_data.iter().collect();
        all.extend([&pos, &conn_a, &offs_a]);
        appended(w, &all)?;
        writeln!(w, "</VTKFile>")
    })
}

/// A time collection: ParaView opens the `.pvd` and steps through `(time, file)` pairs.
/// File names are written relative to the `.pvd`'s directory as given.
pub fn write_pvd(path: &Path, entries: &[(f64, String)]) -> io::Result<()> {
    write_atomic_with(path, |w| {
        writeln!(w, "{HEADER}")?;
        writeln!(
            w,
            r#"<VTKFile type="Collection" version="1.0" byte_order="LittleEndian">"#
        )?;
        writeln!(w, "<Collection>")?;
        for (t, f) in entries {
            writeln!(w, r#"<DataSet timestep="{t}" part="0" file="{f}"/>"#)?;
        }
        writeln!(w, "</Collection>\n</VTKFile>")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn vti_layout_and_length_check() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("f.vti");
        let rho = vec![1.0f64; 6];
        write_vti(
            &p,
            [3, 2, 1],
            [0.0; 3],
            [1.0; 3],
            &[Array::scalar("rho", Values::F64(&rho))],
        )
        .unwrap();
        let bytes = std::fs::read(&p).unwrap();
        let text = String::from_utf8_lossy(&bytes);
        assert!(text.contains(r#"WholeExtent="0 2 0 1 0 0""#));
        // header (8 bytes) + 6 f64 after the '_' marker
        let start = bytes.windows(2).position(|w| w == b"\n_").unwrap() + 2;
        let len = u64::from_le_bytes(bytes[start..start + 8].try_into().unwrap());
        assert_eq!(len, 48);
        let bad = write_vti(
            &p,
            [4, 2, 1],
            [0.0; 3],
            [1.0; 3],
            &[Array::scalar("rho", Values::F64(&rho))],
        );
        assert!(bad.is_err());
    }

    #[test]
    fn vtp_offsets_cover_all_arrays() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("p.vtp");
        let r = vec![0.5f32, 0.7];
        write_vtp_points(
            &p,
            &[[0.0; 3], [1.0, 0.0, 0.0]],
            &[Array::scalar("radius", Values::F32(&r))],
        )
        .unwrap();
        let text = String::from_utf8_lossy(&std::fs::read(&p).unwrap()).into_owned();
        // radius: 8+8 bytes, Points: 8+48, connectivity: 8+8 -> offsets 0, 16, 72, 88
        for off in ["offset=\"0\"", "offset=\"16\"", "offset=\"72\"", "offset=\"88\""] {
            assert!(text.contains(off), "missing {off}");
        }
    }
}
