//! A glTF document builder for import tests (included as `mod gltf_builder`).

use std::path::{Path, PathBuf};

/// A glTF document builder: one buffer (written as `scene.bin` or a data URI), accessors
/// appended as needed.
#[derive(Debug)]
pub struct Gltf {
    pub json: serde_json::Value,
    pub bin: Vec<u8>,
}

impl Default for Gltf {
    fn default() -> Self {
        Self::new()
    }
}

impl Gltf {
    /// A scene with one node pointing at mesh 0 (meshes added by the caller).
    pub fn new() -> Gltf {
        Gltf {
            json: serde_json::json!({
                "asset": {"version": "2.0"},
                "scene": 0,
                "scenes": [{"nodes": [0]}],
                "nodes": [{"mesh": 0}],
                "meshes": [],
                "accessors": [],
                "bufferViews": [],
                "buffers": [],
            }),
            bin: Vec::new(),
        }
    }

    /// Appends raw bytes as a buffer view; returns its index.
    pub fn view(&mut self, bytes: &[u8], stride: Option<usize>) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let mut v = serde_json::json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()});
        if let Some(s) = stride {
            v["byteStride"] = s.into();
        }
        self.bin.extend_from_slice(bytes);
        let views = self.json["bufferViews"].as_array_mut().unwrap();
        views.push(v);
        views.len() - 1
    }

    /// Adds an accessor; returns its index.
    pub fn accessor(
        &mut self,
        view: Option<usize>,
        component: u32,
        count: usize,
        ty: &str,
        extra: serde_json::Value,
    ) -> usize {
        let mut a = serde_json::json!({"componentType": component, "count": count, "type": ty});
        if let Some(v) = view {
            a["bufferView"] = v.into();
        }
        if let Some(o) = extra.as_object() {
            for (k, v) in o {
                a[k] = v.clone();
            }
        }
        let acc = self.json["accessors"].as_array_mut().unwrap();
        acc.push(a);
        acc.len() - 1
    }

    /// Adds a float VEC3 position accessor with min/max.
    pub fn positions(&mut self, p: &[[f32; 3]]) -> usize {
        let bytes: Vec<u8> = p.iter().flatten().flat_map(|f| f.to_le_bytes()).collect();
        let v = self.view(&bytes, None);
        let finite: Vec<[f32; 3]> = p.iter().copied().filter(|q| q.iter().all(|c| c.is_finite())).collect();
        let lo: Vec<f32> =
            (0..3).map(|a| finite.iter().map(|q| q[a]).fold(f32::INFINITY, f32::min)).collect();
        let hi: Vec<f32> =
            (0..3).map(|a| finite.iter().map(|q| q[a]).fold(f32::NEG_INFINITY, f32::max)).collect();
        self.accessor(Some(v), 5126, p.len(), "VEC3", serde_json::json!({"min": lo, "max": hi}))
    }

    /// Adds u32 indices.
    pub fn indices(&mut self, idx: &[u32]) -> usize {
        let bytes: Vec<u8> = idx.iter().flat_map(|i| i.to_le_bytes()).collect();
        let v = self.view(&bytes, None);
        self.accessor(Some(v), 5125, idx.len(), "SCALAR", serde_json::json!({}))
    }

    /// Adds a mesh with one primitive.
    pub fn mesh(&mut self, primitive: serde_json::Value) {
        self.json["meshes"].as_array_mut().unwrap().push(serde_json::json!({"primitives": [primitive]}));
    }

    /// Gives mesh 0's first primitive texture coordinates and material 0 (`material`, whose
    /// textures all use texture 0 showing the image at `uri`).
    pub fn textured(&mut self, material: serde_json::Value, uri: &str) {
        let tc: Vec<u8> = [[0.0f32, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]]
            .iter()
            .flatten()
            .flat_map(|v| v.to_le_bytes())
            .collect();
        let v = self.view(&tc, None);
        let a = self.accessor(Some(v), 5126, 4, "VEC2", serde_json::json!({}));
        let prim = &mut self.json["meshes"][0]["primitives"][0];
        prim["attributes"]["TEXCOORD_0"] = a.into();
        prim["material"] = 0.into();
        self.json["materials"] = serde_json::json!([material]);
        self.json["textures"] = serde_json::json!([{"source": 0}]);
        self.json["images"] = serde_json::json!([{ "uri": uri }]);
    }

    /// Rewrites the buffer URI of a written `.gltf`.
    pub fn set_buffer_uri(path: &Path, uri: &str) {
        let mut j: serde_json::Value = serde_json::from_slice(&std::fs::read(path).unwrap()).unwrap();
        j["buffers"][0]["uri"] = uri.into();
        std::fs::write(path, serde_json::to_vec(&j).unwrap()).unwrap();
    }

    /// A one-quad scene (two triangles).
    pub fn quad() -> Gltf {
        let mut g = Gltf::new();
        let p = g.positions(&[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]);
        let i = g.indices(&[0, 1, 2, 0, 2, 3]);
        g.mesh(serde_json::json!({"attributes": {"POSITION": p}, "indices": i}));
        g
    }

    /// Writes `name.gltf` and `name.bin` into `dir`; returns the .gltf path.
    pub fn write(&mut self, dir: &Path, name: &str) -> PathBuf {
        self.json["buffers"] =
            serde_json::json!([{"uri": format!("{name}.bin"), "byteLength": self.bin.len()}]);
        std::fs::write(dir.join(format!("{name}.bin")), &self.bin).unwrap();
        let path = dir.join(format!("{name}.gltf"));
        std::fs::write(&path, serde_json::to_vec_pretty(&self.json).unwrap()).unwrap();
        path
    }

    /// Writes a `.glb` with the buffer in its binary chunk.
    pub fn write_glb(&mut self, dir: &Path, name: &str) -> PathBuf {
        self.json["buffers"] = serde_json::json!([{"byteLength": self.bin.len()}]);
        let path = dir.join(format!("{name}.glb"));
        std::fs::write(&path, glb(&self.json, &self.bin)).unwrap();
        path
    }
}

/// A GLB 2.0 of `json` and `bin`: a 12-byte header, a JSON chunk and a BIN chunk, each padded
/// to 4 bytes.
pub fn glb(json: &serde_json::Value, bin: &[u8]) -> Vec<u8> {
    let mut json = serde_json::to_vec(json).unwrap();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut bin = bin.to_vec();
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}

/// Writes `white.png` (2 × 2 opaque white) into `dir`: the texture the material tests' glTF
/// documents name.
#[allow(dead_code)] // Not every test file that includes this module names a texture.
pub fn write_white_png(dir: &Path) {
    image::RgbaImage::from_pixel(2, 2, image::Rgba([255, 255, 255, 255]))
        .save(dir.join("white.png"))
        .unwrap();
}
