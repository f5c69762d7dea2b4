//! The predicted part as a PLY mesh (writer): the machined surface's points with their
//! outward normals and the deviation along the normal, and the triangles joining them
//! ([`crate::machining::dexel::surface::SurfaceMesh`]). MeshLab shows the deviation as the
//! vertices' `quality`, ParaView as a point array of that name.
//!
//! Units: metres for positions and the deviation (> 0 material left, < 0 overcut); the
//! header says so in a comment.

use std::io::{self, Write};
use std::vec::Vec;

use crate::machining::dexel::surface::{Face, SurfaceMesh};

/// How the PLY body is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Format {
    /// Little-endian binary (32-bit floats): compact, what the viewers read fastest.
    #[default]
    Binary,
    /// One line per vertex and per face.
    Ascii,
}

fn face_code(f: Face) -> u8 {
    match f {
        Face::PlusX => 0,
        Face::MinusX => 1,
        Face::PlusY => 2,
        Face::MinusY => 3,
        Face::PlusZ => 4,
        Face::MinusZ => 5,
    }
}

/// Writes `mesh` to `out`: per vertex `x y z nx ny nz quality face` (float, float, uchar;
/// `quality` the deviation \[m\], `face` the outward normal's side, 0..5 for +x -x +y -y +z
/// -z), per face its three vertex indices.
pub fn write<W: Write>(mesh: &SurfaceMesh, format: Format, mut out: W) -> io::Result<()> {
    let kind = match format {
        Format::Binary => "binary_little_endian",
        Format::Ascii => "ascii",
    };
    write!(
        out,
        "ply\nformat {kind} 1.0\ncomment deflect: the machined surface, metres; quality = \
         deviation along the outward normal (> 0 material left, < 0 overcut)\n\
         element vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
         property float nx\nproperty float ny\nproperty float nz\nproperty float quality\n\
         property uchar face\nelement face {}\nproperty list uchar int vertex_indices\n\
         end_header\n",
        mesh.points.len(),
        mesh.triangles.len()
    )?;
    match format {
        Format::Ascii => {
            for p in &mesh.points {
                let (x, n) = (p.position, p.normal);
                writeln!(
                    out,
                    "{} {} {} {} {} {} {} {}",
                    x.x as f32,
                    x.y as f32,
                    x.z as f32,
                    n.x as f32,
                    n.y as f32,
                    n.z as f32,
                    p.deviation as f32,
                    face_code(Face::of(p))
                )?;
            }
            for t in &mesh.triangles {
                let [a, b, c] = *t;
                writeln!(out, "3 {a} {b} {c}")?;
            }
        }
        Format::Binary => {
            let mut buf = Vec::with_capacity(29 * 4096);
            for chunk in mesh.points.chunks(4096) {
                buf.clear();
                for p in chunk {
                    let (x, n) = (p.position, p.normal);
                    for v in [x.x, x.y, x.z, n.x, n.y, n.z, p.deviation] {
                        buf.extend_from_slice(&(v as f32).to_le_bytes());
                    }
                    buf.push(face_code(Face::of(p)));
                }
                out.write_all(&buf)?;
            }
            for chunk in mesh.triangles.chunks(4096) {
                buf.clear();
                for t in chunk {
                    buf.push(3);
                    for k in t {
                        // Indices below 2^31: the mesh holds at most u32::MAX vertices and
                        // PLY's `int` is signed, so larger ones are refused here.
                        let k = i32::try_from(*k).map_err(|_| {
                            io::Error::new(
                                io::ErrorKind::InvalidInput,
                                "PLY vertex index past 2^31",
                            )
                        })?;
                        buf.extend_from_slice(&k.to_le_bytes());
                    }
                }
                out.write_all(&buf)?;
            }
        }
    }
    out.flush()
}
