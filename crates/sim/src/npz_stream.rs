//! A `.npz` archive written a row at a time: each array goes to its own `.npy` file in a
//! temporary folder as the rows come (the header reserved, its shape patched at the end),
//! then the files are stored (not compressed: the archive is written at disk speed) into
//! the archive. Memory stays at the write buffers whatever the row count; `numpy.load`
//! reads the result, and `pandas.DataFrame` takes its 1-D arrays.

use std::fs::File;
use std::io::{BufWriter, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

use crate::SimError;

/// An array's element type.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dtype {
    /// `<f8`.
    F64,
    /// `<i8`.
    I64,
    /// `|b1`.
    Bool,
}

impl Dtype {
    fn descr(self) -> &'static str {
        match self {
            Self::F64 => "<f8",
            Self::I64 => "<i8",
            Self::Bool => "|b1",
        }
    }
}

/// The reserved `.npy` header: magic, version 1.0, its length, the dict padded to 128 bytes.
const HEADER: usize = 128;

fn header(dtype: Dtype, rows: usize, width: usize) -> Vec<u8> {
    let shape = if width == 0 {
        format!("({rows},)")
    } else {
        format!("({rows}, {width})")
    };
    let dict = format!(
        "{{'descr': '{}', 'fortran_order': False, 'shape': {shape}, }}",
        dtype.descr()
    );
    let mut h = Vec::with_capacity(HEADER);
    h.extend_from_slice(b"\x93NUMPY\x01\x00");
    let len = (HEADER - 10) as u16;
    h.extend_from_slice(&len.to_le_bytes());
    h.extend_from_slice(dict.as_bytes());
    while h.len() < HEADER - 1 {
        h.push(b' ');
    }
    h.push(b'\n');
    h
}

struct Column {
    name: String,
    dtype: Dtype,
    width: usize,
    path: PathBuf,
    file: BufWriter<File>,
}

/// The archive being written (see the module docs).
pub struct NpzStream {
    target: PathBuf,
    dir: PathBuf,
    columns: Vec<Column>,
    rows: usize,
}

impl std::fmt::Debug for NpzStream {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NpzStream")
            .field("target", &self.target)
            .field("rows", &self.rows)
            .finish_non_exhaustive()
    }
}

impl NpzStream {
    /// An archive to be written at `target`; its arrays are kept in a folder next to it
    /// (`.<name>.parts`) until [`Self::finish`].
    pub fn create(target: &Path) -> Result<Self, SimError> {
        let name = target
            .file_name()
            .map_or_else(|| "samples".into(), |n| n.to_string_lossy().into_owned());
        let dir = target.with_file_name(format!(".{name}.parts"));
        std::fs::create_dir_all(&dir)
            .map_err(|e| SimError::file(&dir, "create the folder of the archive's parts", e))?;
        Ok(Self {
            target: target.to_path_buf(),
            dir,
            columns: Vec::new(),
            rows: 0,
        })
    }

    /// A new array `name` of `dtype`, `width` values per row (0: a 1-D array); its index.
    pub fn array(&mut self, name: &str, dtype: Dtype, width: usize) -> Result<usize, SimError> {
        let path = self.dir.join(format!("{name}.npy"));
        // Read back at the end: opened for both.
        let file = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(true)
            .open(&path)
            .map_err(|e| SimError::file(&path, "create", e))?;
        let mut file = BufWriter::with_capacity(1 << 16, file);
        file.write_all(&header(dtype, 0, width))
            .map_err(|e| SimError::file(&path, "write", e))?;
        self.columns.push(Column {
            name: name.to_string(),
            dtype,
            width,
            path,
            file,
        });
        Ok(self.columns.len() - 1)
    }

    fn write(&mut self, array: usize, bytes: &[u8]) -> Result<(), SimError> {
        let c = self
            .columns
            .get_mut(array)
            .ok_or_else(|| SimError::new("npz: no such array"))?;
        c.file
            .write_all(bytes)
            .map_err(|e| SimError::file(&c.path, "write", e))
    }

    /// Appends `values` (a row's, or several rows') to an `F64` array.
    pub fn f64s(&mut self, array: usize, values: &[f64]) -> Result<(), SimError> {
        let mut bytes = [0u8; 8 * 16];
        for chunk in values.chunks(16) {
            for (slot, v) in bytes.chunks_mut(8).zip(chunk) {
                slot.copy_from_slice(&v.to_le_bytes());
            }
            self.write(array, &bytes[..8 * chunk.len()])?;
        }
        Ok(())
    }

    /// Appends a value to an `I64` array.
    pub fn i64(&mut self, array: usize, v: i64) -> Result<(), SimError> {
        self.write(array, &v.to_le_bytes())
    }

    /// Appends a value to a `Bool` array.
    pub fn bool(&mut self, array: usize, v: bool) -> Result<(), SimError> {
        self.write(array, &[u8::from(v)])
    }

    /// Counts a row written to every array.
    pub fn row_done(&mut self) {
        self.rows += 1;
    }

    /// Patches every header with the row count, stores the arrays in the archive and
    /// removes the parts. Returns the archive's size \[bytes\].
    pub fn finish(self) -> Result<u64, SimError> {
        let target = self.target.clone();
        let zerr = |e: &dyn std::fmt::Display| SimError::file(&target, "write the archive", e);
        let out = File::create(&target).map_err(|e| zerr(&e))?;
        let mut zip = zip::ZipWriter::new(BufWriter::with_capacity(1 << 20, out));
        let options = zip::write::SimpleFileOptions::default()
            .compression_method(zip::CompressionMethod::Stored)
            .large_file(true);
        for c in self.columns {
            let path = c.path.clone();
            let mut file = c
                .file
                .into_inner()
                .map_err(|e| SimError::file(&path, "write", e.error()))?;
            file.seek(SeekFrom::Start(0))
                .and_then(|_| file.write_all(&header(c.dtype, self.rows, c.width)))
                .and_then(|()| file.seek(SeekFrom::Start(0)))
                .map_err(|e| SimError::file(&path, "write the header of", e))?;
            zip.start_file(format!("{}.npy", c.name), options)
                .map_err(|e| zerr(&e))?;
            std::io::copy(&mut file, &mut zip).map_err(|e| zerr(&e))?;
            drop(file);
            let _ = std::fs::remove_file(&path);
        }
        let mut out = zip.finish().map_err(|e| zerr(&e))?;
        out.flush().map_err(|e| zerr(&e))?;
        let _ = std::fs::remove_dir(&self.dir);
        std::fs::metadata(&target)
            .map(|m| m.len())
            .map_err(|e| SimError::file(&target, "read back", e))
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn headers_are_128_bytes_and_say_the_shape() {
        for (rows, width) in [(0, 0), (7_200_000, 6), (usize::MAX >> 4, 3)] {
            let h = header(Dtype::F64, rows, width);
            assert_eq!(h.len(), HEADER);
            assert_eq!(&h[..8], b"\x93NUMPY\x01\x00");
            assert_eq!(u16::from_le_bytes([h[8], h[9]]) as usize, HEADER - 10);
            assert_eq!(*h.last().unwrap(), b'\n');
            let text = String::from_utf8_lossy(&h[10..]);
            assert!(text.contains(&format!("'shape': ({rows}")), "{text}");
        }
    }

    #[test]
    fn an_archive_holds_its_arrays_row_by_row() {
        let dir = std::env::temp_dir().join(format!("deflect-npz-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let target = dir.join("t.npz");
        let mut z = NpzStream::create(&target).unwrap();
        let (a, b, c) = (
            z.array("a", Dtype::F64, 0).unwrap(),
            z.array("b", Dtype::F64, 2).unwrap(),
            z.array("c", Dtype::I64, 0).unwrap(),
        );
        for k in 0..5 {
            z.f64s(a, &[k as f64]).unwrap();
            z.f64s(b, &[k as f64, -(k as f64)]).unwrap();
            z.i64(c, k).unwrap();
            z.row_done();
        }
        z.finish().unwrap();
        let mut archive = zip::ZipArchive::new(File::open(&target).unwrap()).unwrap();
        let mut names: Vec<String> = archive.file_names().map(str::to_string).collect();
        names.sort();
        assert_eq!(names, ["a.npy", "b.npy", "c.npy"]);
        let mut b_bytes = Vec::new();
        std::io::Read::read_to_end(&mut archive.by_name("b.npy").unwrap(), &mut b_bytes).unwrap();
        assert_eq!(b_bytes.len(), HEADER + 5 * 2 * 8);
        assert!(String::from_utf8_lossy(&b_bytes[..HEADER]).contains("'shape': (5, 2)"));
        let v = f64::from_le_bytes(b_bytes[HEADER + 8 * 3..HEADER + 8 * 4].try_into().unwrap());
        assert_eq!(v, -1.0);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
