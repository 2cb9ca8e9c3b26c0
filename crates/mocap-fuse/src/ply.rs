//! Point clouds in PLY files (a depth sensor's scan of the room), read and
//! written with `ply-rs-bw`.
//!
//! [`read_ply_points`] reads the `x y z` of the `vertex` element of ASCII,
//! binary little-endian and binary big-endian files (`float` or `double`
//! coordinates; other properties and elements, such as colours, normals and
//! faces, are skipped). Positions are in metres, in the sensor's camera space
//! (Kinect convention: z forward out of the lens, y up), as
//! [`crate::sim::sensor_point_cloud`] makes them.

use std::io::BufReader;
use std::path::Path;

use mocap_core::error::Location;
use mocap_core::rotation::Vec3;
use mocap_core::{Error, ParseError, Result};
use ply_rs_bw::parser::{Parser, Reader};
use ply_rs_bw::ply::{
    Addable, ElementDef, Encoding, Ply, Property, PropertyAccess, PropertyAccessResult,
    PropertyDef, PropertyType, ScalarType,
};

/// One vertex as the parser fills it: which coordinates it has seen.
#[derive(Debug, Clone, Copy, Default)]
struct Vertex {
    xyz: [f64; 3],
    seen: [bool; 3],
}

impl PropertyAccess for Vertex {
    fn new() -> Self {
        Vertex::default()
    }

    fn set_property(&mut self, key: &str, property: Property) -> PropertyAccessResult {
        let k = match key {
            "x" => 0,
            "y" => 1,
            "z" => 2,
            _ => return PropertyAccessResult::Ignored,
        };
        let value = match property {
            Property::Float(v) => v as f64,
            Property::Double(v) => v,
            _ => return PropertyAccessResult::UnsupportedType,
        };
        self.xyz[k] = value;
        self.seen[k] = true;
        PropertyAccessResult::Set
    }

    fn get_float(&self, key: &str) -> Option<f32> {
        match key {
            "x" => Some(self.xyz[0] as f32),
            "y" => Some(self.xyz[1] as f32),
            "z" => Some(self.xyz[2] as f32),
            _ => None,
        }
    }
}

/// Any other element: read and dropped.
struct Skipped;

impl PropertyAccess for Skipped {
    fn new() -> Self {
        Skipped
    }
}

fn ply_error(path: &Path, line: Option<usize>, message: String) -> Error {
    Error::Parse(ParseError {
        location: Location {
            path: path.to_path_buf(),
            line: line.unwrap_or(1),
            column: 1,
        },
        message,
    })
}

/// Reads the vertex positions of a PLY file.
pub fn read_ply_points(path: &Path) -> Result<Vec<Vec3>> {
    let file = std::fs::File::open(path).map_err(|e| Error::io(path, e))?;
    let mut reader = Reader::new(BufReader::new(file));
    let vertex_parser = Parser::<Vertex>::new();
    let header = vertex_parser.read_header(&mut reader).map_err(|e| {
        ply_error(
            path,
            e.line(),
            format!("expected a PLY header (ply, format, element vertex with x y z properties, end_header): {e}"),
        )
    })?;
    let mut points = None;
    for (_, element) in &header.elements {
        if element.name == "vertex" {
            for axis in ["x", "y", "z"] {
                match element.properties.get(axis).map(|p| &p.data_type) {
                    Some(PropertyType::Scalar(ScalarType::Float | ScalarType::Double)) => {}
                    Some(other) => {
                        return Err(ply_error(
                            path,
                            None,
                            format!(
                                "vertex property {axis} must be a float or double, it is {other:?}"
                            ),
                        ))
                    }
                    None => {
                        return Err(ply_error(
                            path,
                            None,
                            format!("the vertex element has no {axis} property"),
                        ))
                    }
                }
            }
            let vertices = vertex_parser
                .read_payload_for_element(&mut reader, element, &header)
                .map_err(|e| {
                    ply_error(
                        path,
                        e.line(),
                        format!("expected {} vertices: {e}", element.count),
                    )
                })?;
            let mut out = Vec::with_capacity(vertices.len());
            for (i, v) in vertices.iter().enumerate() {
                if !v.xyz.iter().all(|c| c.is_finite()) {
                    return Err(ply_error(
                        path,
                        None,
                        format!("vertex {i} has a coordinate that is not a finite number"),
                    ));
                }
                out.push(Vec3::new(v.xyz[0] as f32, v.xyz[1] as f32, v.xyz[2] as f32));
            }
            points = Some(out);
            // Elements after the vertices need not be read.
            break;
        }
        Parser::<Skipped>::new()
            .read_payload_for_element(&mut reader, element, &header)
            .map_err(|e| {
                ply_error(
                    path,
                    e.line(),
                    format!("reading element {:?}: {e}", element.name),
                )
            })?;
    }
    points.ok_or_else(|| ply_error(path, None, "the file has no vertex element".into()))
}

/// How a PLY file is written.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PlyEncoding {
    Ascii,
    BinaryLittleEndian,
}

/// Writes points as the vertices (`float x y z`) of a PLY file, atomically.
pub fn write_ply_points(
    path: &Path,
    points: &[Vec3],
    encoding: PlyEncoding,
    comment: &str,
) -> Result<()> {
    let mut ply = Ply::<Vertex>::new();
    ply.header.encoding = match encoding {
        PlyEncoding::Ascii => Encoding::Ascii,
        PlyEncoding::BinaryLittleEndian => Encoding::BinaryLittleEndian,
    };
    if !comment.is_empty() {
        ply.header.comments.push(comment.replace('\n', " "));
    }
    let mut vertex = ElementDef::new("vertex".to_string());
    for axis in ["x", "y", "z"] {
        vertex.properties.add(PropertyDef::new(
            axis.to_string(),
            PropertyType::Scalar(ScalarType::Float),
        ));
    }
    ply.header.elements.add(vertex);
    ply.payload.insert(
        "vertex".to_string(),
        points
            .iter()
            .map(|p| Vertex {
                xyz: [p.x as f64, p.y as f64, p.z as f64],
                seen: [true; 3],
            })
            .collect(),
    );
    let mut bytes = Vec::new();
    ply_rs_bw::writer::Writer::<Vertex>::new()
        .write_ply(&mut bytes, &mut ply)
        .map_err(|e| Error::io(path, e))?;
    mocap_core::io::atomic::write_bytes_atomically(path, &bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ascii_and_binary_round_trip() {
        let dir = tempfile::tempdir().unwrap();
        let points = vec![
            Vec3::new(0.5, -1.25, 3.0),
            Vec3::new(1e-3, 2.0, 4.5),
            Vec3::new(-2.0, 0.0, 0.75),
        ];
        for encoding in [PlyEncoding::Ascii, PlyEncoding::BinaryLittleEndian] {
            let path = dir.path().join(format!("{encoding:?}.ply"));
            write_ply_points(&path, &points, encoding, "test cloud").unwrap();
            let text = std::fs::read(&path).unwrap();
            let expected_format = match encoding {
                PlyEncoding::Ascii => "format ascii 1.0",
                PlyEncoding::BinaryLittleEndian => "format binary_little_endian 1.0",
            };
            assert!(
                String::from_utf8_lossy(&text).contains(expected_format),
                "{encoding:?}"
            );
            assert_eq!(read_ply_points(&path).unwrap(), points);
        }
    }

    #[test]
    fn other_exporters_files_are_read() {
        // Double coordinates, colours, normals, a face element, and an
        // element before the vertices.
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("scan.ply");
        std::fs::write(
            &path,
            "ply\nformat ascii 1.0\ncomment from a scanner\nelement camera 1\nproperty float fx\n\
             element vertex 2\nproperty double x\nproperty double y\nproperty double z\n\
             property float nx\nproperty float ny\nproperty float nz\nproperty uchar red\n\
             property uchar green\nproperty uchar blue\nelement face 1\n\
             property list uchar int vertex_indices\nend_header\n525.0\n\
             1.5 2.5 3.5 0 0 1 255 0 0\n-1 0 2 0 1 0 0 255 0\n3 0 1 1\n",
        )
        .unwrap();
        let points = read_ply_points(&path).unwrap();
        assert_eq!(
            points,
            vec![Vec3::new(1.5, 2.5, 3.5), Vec3::new(-1.0, 0.0, 2.0)]
        );
    }

    #[test]
    fn bad_files_say_what_is_wrong() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("bad.ply");
        let check = |text: &str, expected: &str| {
            std::fs::write(&path, text).unwrap();
            let err = read_ply_points(&path).unwrap_err().to_string();
            assert!(err.contains("bad.ply"), "{err}");
            assert!(err.contains(expected), "{expected:?} in {err}");
        };
        check("not a ply file\n", "expected a PLY header");
        check(
            "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nend_header\n1 2\n3 4\n",
            "no z property",
        );
        check(
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 2 3\n4 5 6\n",
            "expected 3 vertices",
        );
        check(
            "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\nproperty float z\nend_header\n1 nan 3\n",
            "",
        );
        check(
            "ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int vertex_indices\nend_header\n",
            "no vertex element",
        );
    }
}
