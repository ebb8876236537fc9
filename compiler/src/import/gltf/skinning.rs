//! Skinned meshes posed as their joint nodes stand: the joints' matrices in the rest pose and
//! the per-vertex blend of them (glTF 2.0, "Skins"; kiln bakes no animation).

use ::gltf::accessor::{DataType, Dimensions};
use glam::DMat4;

use super::Importer;
use crate::exit::{CliError, CliResult};

impl Importer<'_> {
    /// Joint matrices of `skin` in the rest pose: each joint's scene transform times its inverse
    /// bind matrix (glTF 2.0, "Skins"; the skinned node's own transform is ignored). At the bind
    /// pose they are the identity and the mesh stays where its positions put it.
    pub(super) fn joint_matrices(&mut self, skin: &::gltf::Skin, node: usize) -> CliResult<Vec<DMat4>> {
        let at = format!("{}: skin {} (node {node})", self.file, skin.index());
        let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
        if joints.is_empty() {
            return Err(CliError::input(format!("{at} has no joints")));
        }
        let inverse_bind: Vec<DMat4> = match skin.inverse_bind_matrices() {
            Some(acc) => {
                self.check_accessor(
                    &acc,
                    &at,
                    "inverseBindMatrices",
                    &[Dimensions::Mat4],
                    &[DataType::F32],
                    false,
                )?;
                if acc.count() < joints.len() {
                    return Err(CliError::input(format!(
                        "{at}: inverseBindMatrices accessor {} has {} matrices for {} joints",
                        acc.index(),
                        acc.count(),
                        joints.len()
                    )));
                }
                let reader = skin.reader(|b| self.buffers.get(b.index()).map(Vec::as_slice));
                let raw: Vec<[[f32; 4]; 4]> =
                    reader.read_inverse_bind_matrices().map(|it| it.collect()).unwrap_or_default();
                if let Some((i, m)) =
                    raw.iter().enumerate().find(|(_, m)| !m.as_flattened().iter().all(|v| v.is_finite()))
                {
                    return Err(CliError::input(format!(
                        "{at}: inverseBindMatrices accessor {} element {i} is not finite: {m:?}",
                        acc.index()
                    )));
                }
                raw.iter().map(|m| DMat4::from_cols_array_2d(&m.map(|c| c.map(f64::from)))).collect()
            }
            None => vec![DMat4::IDENTITY; joints.len()],
        };
        let mut out = Vec::with_capacity(joints.len());
        for (j, ibm) in joints.iter().zip(&inverse_bind) {
            let m = self.global_transform(*j)? * *ibm;
            if !m.is_finite() {
                return Err(CliError::input(format!("{at}: joint node {j} has a non-finite transform")));
            }
            out.push(m);
        }
        if self.doc.animations().next().is_some() {
            self.scene.warn(format!(
                "{at}: skinned mesh posed as its joint nodes stand without animation; the animation is not baked"
            ));
        }
        Ok(out)
    }

    /// Per-vertex skinning matrices: Σ weight · joint matrix over JOINTS_n/WEIGHTS_n (sets 0
    /// and 1), weights normalised to sum 1 (glTF requires it up to rounding); a vertex with no
    /// weight keeps its mesh-space position. `None` when the primitive has no weights at all.
    pub(super) fn skin_matrices(
        &self,
        prim: &::gltf::Primitive,
        joints: &[DMat4],
        count: usize,
        at: &str,
    ) -> CliResult<Option<Vec<DMat4>>> {
        let reader = prim.reader(|b| self.buffers.get(b.index()).map(Vec::as_slice));
        let mut sum = vec![DMat4::ZERO; count];
        let mut total = vec![0.0f64; count];
        let mut any = false;
        for set in 0..2 {
            let (Some(ja), Some(wa)) =
                (prim.get(&::gltf::Semantic::Joints(set)), prim.get(&::gltf::Semantic::Weights(set)))
            else {
                continue;
            };
            let (jn, wn) = (format!("JOINTS_{set}"), format!("WEIGHTS_{set}"));
            self.check_accessor(&ja, at, &jn, &[Dimensions::Vec4], &[DataType::U8, DataType::U16], false)?;
            self.check_accessor(
                &wa,
                at,
                &wn,
                &[Dimensions::Vec4],
                &[DataType::F32, DataType::U8, DataType::U16],
                true,
            )?;
            self.check_count(&ja, count, at, &jn)?;
            self.check_count(&wa, count, at, &wn)?;
            let js: Vec<[u16; 4]> =
                reader.read_joints(set).map(|j| j.into_u16().collect()).unwrap_or_default();
            let ws: Vec<[f32; 4]> =
                reader.read_weights(set).map(|w| w.into_f32().collect()).unwrap_or_default();
            for (i, (j, w)) in js.iter().zip(&ws).enumerate() {
                for k in 0..4 {
                    if !(w[k].is_finite() && w[k] >= 0.0) {
                        return Err(CliError::input(format!(
                            "{at}: {wn} accessor {} element {i} is not a finite weight ≥ 0: {w:?}",
                            wa.index()
                        )));
                    }
                    if w[k] == 0.0 {
                        continue;
                    }
                    let m = joints.get(j[k] as usize).ok_or_else(|| {
                        CliError::input(format!(
                            "{at}: {jn} accessor {} element {i} names joint {} of a skin with {}",
                            ja.index(),
                            j[k],
                            joints.len()
                        ))
                    })?;
                    sum[i] += *m * w[k] as f64;
                    total[i] += w[k] as f64;
                    any = true;
                }
            }
        }
        if !any {
            return Ok(None);
        }
        Ok(Some(
            sum.into_iter()
                .zip(total)
                .map(|(m, t)| if t > 0.0 { m * (1.0 / t) } else { DMat4::IDENTITY })
                .collect(),
        ))
    }
}
