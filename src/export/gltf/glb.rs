//! The binary glTF container: one buffer of typed accessors and images, and the `.glb` bytes.
//!
//! In: data appended through [`Buffer`] (each call one buffer view, 4-byte aligned, and for
//! typed data one accessor with its `min`/`max` where glTF asks for them), then the document's
//! JSON. Out: the GLB (glTF 2.0 §4.4): a 12-byte header, the JSON chunk padded with spaces, the
//! BIN chunk padded with zeros, all little-endian.

use serde_json::{json, Map, Value};

/// `ARRAY_BUFFER`: a buffer view of vertex attributes.
pub const ARRAY_BUFFER: u32 = 34962;
/// `ELEMENT_ARRAY_BUFFER`: a buffer view of indices.
pub const ELEMENT_ARRAY_BUFFER: u32 = 34963;

const FLOAT: u32 = 5126;
const UNSIGNED_SHORT: u32 = 5123;
const UNSIGNED_INT: u32 = 5125;

/// The document's one binary buffer, its views and accessors.
#[derive(Default)]
pub struct Buffer {
    bytes: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

/// The number of components of an accessor type.
fn components(kind: &str) -> usize {
    match kind {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" | "MAT2" => 4,
        "MAT3" => 9,
        "MAT4" => 16,
        _ => unreachable!("accessor type {kind}"),
    }
}

impl Buffer {
    /// Appends `data` as a buffer view (with `target` when it holds vertex data or indices);
    /// returns the view's index.
    pub fn view(&mut self, data: &[u8], target: Option<u32>) -> usize {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        let mut view = Map::new();
        view.insert("buffer".into(), json!(0));
        view.insert("byteOffset".into(), json!(self.bytes.len()));
        view.insert("byteLength".into(), json!(data.len()));
        if let Some(t) = target {
            view.insert("target".into(), json!(t));
        }
        self.bytes.extend_from_slice(data);
        self.views.push(Value::Object(view));
        self.views.len() - 1
    }

    /// Floats of accessor type `kind` (`VEC3`, …), with per-component `min`/`max` when
    /// `bounds`; returns the accessor's index.
    pub fn floats(&mut self, data: &[f32], kind: &str, bounds: bool, target: Option<u32>) -> usize {
        let n = components(kind);
        let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, target);
        let mut accessor = json!({
            "bufferView": view,
            "componentType": FLOAT,
            "count": data.len() / n,
            "type": kind,
        });
        if bounds {
            let mut lo = vec![f32::INFINITY; n];
            let mut hi = vec![f32::NEG_INFINITY; n];
            for chunk in data.chunks(n) {
                for (k, &v) in chunk.iter().enumerate() {
                    lo[k] = lo[k].min(v);
                    hi[k] = hi[k].max(v);
                }
            }
            accessor["min"] = json!(lo);
            accessor["max"] = json!(hi);
        }
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    /// Joint indices, four per vertex (`VEC4` of unsigned shorts).
    pub fn joints(&mut self, data: &[u16]) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(ARRAY_BUFFER));
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": UNSIGNED_SHORT,
            "count": data.len() / 4,
            "type": "VEC4",
        }));
        self.accessors.len() - 1
    }

    /// Triangle indices (`SCALAR` unsigned ints).
    pub fn indices(&mut self, data: &[u32]) -> usize {
        let bytes: Vec<u8> = data.iter().flat_map(|v| v.to_le_bytes()).collect();
        let view = self.view(&bytes, Some(ELEMENT_ARRAY_BUFFER));
        self.accessors.push(json!({
            "bufferView": view,
            "componentType": UNSIGNED_INT,
            "count": data.len(),
            "type": "SCALAR",
        }));
        self.accessors.len() - 1
    }

    /// Puts the buffer, views and accessors into `document` and returns the GLB bytes.
    pub fn into_glb(mut self, mut document: Map<String, Value>) -> Vec<u8> {
        while !self.bytes.len().is_multiple_of(4) {
            self.bytes.push(0);
        }
        if !self.bytes.is_empty() {
            document.insert(
                "buffers".into(),
                json!([{ "byteLength": self.bytes.len() }]),
            );
            document.insert("bufferViews".into(), Value::Array(self.views));
            document.insert("accessors".into(), Value::Array(self.accessors));
        }
        let mut text = Value::Object(document).to_string().into_bytes();
        while !text.len().is_multiple_of(4) {
            text.push(b' ');
        }
        let chunks = 8
            + text.len()
            + if self.bytes.is_empty() {
                0
            } else {
                8 + self.bytes.len()
            };
        let mut out = Vec::with_capacity(12 + chunks);
        out.extend_from_slice(b"glTF");
        out.extend_from_slice(&2u32.to_le_bytes());
        out.extend_from_slice(&((12 + chunks) as u32).to_le_bytes());
        out.extend_from_slice(&(text.len() as u32).to_le_bytes());
        out.extend_from_slice(b"JSON");
        out.extend_from_slice(&text);
        if !self.bytes.is_empty() {
            out.extend_from_slice(&(self.bytes.len() as u32).to_le_bytes());
            out.extend_from_slice(b"BIN\0");
            out.extend_from_slice(&self.bytes);
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_container_has_aligned_chunks_and_the_declared_length() {
        let mut buffer = Buffer::default();
        let a = buffer.floats(&[1.0, -2.0, 3.0], "VEC3", true, Some(ARRAY_BUFFER));
        buffer.view(&[1, 2, 3], None);
        let b = buffer.indices(&[0, 1, 2]);
        assert_eq!((a, b), (0, 1));
        let mut doc = Map::new();
        doc.insert("asset".into(), json!({ "version": "2.0" }));
        let glb = buffer.into_glb(doc);
        assert_eq!(&glb[0..4], b"glTF");
        let length = u32::from_le_bytes(glb[8..12].try_into().unwrap()) as usize;
        assert_eq!(length, glb.len());
        let json_len = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
        assert_eq!(json_len % 4, 0);
        let text: Value = serde_json::from_slice(&glb[20..20 + json_len]).unwrap();
        assert_eq!(text["accessors"][0]["max"], json!([1.0, -2.0, 3.0]));
        // The index view starts 4-byte aligned after the 3-byte view.
        assert_eq!(text["bufferViews"][2]["byteOffset"], json!(16));
        let bin = 20 + json_len;
        assert_eq!(&glb[bin + 4..bin + 8], b"BIN\0");
    }
}
