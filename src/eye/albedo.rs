//! The albedo each pixel is shaded with, from the colours the user's files
//! carry (`softshadow.Material`, read by `Scene.from_trimesh`).
//!
//! A mesh's material is one of:
//!
//! * **Constant**: its colour `color` (glTF `baseColorFactor`, OBJ `Kd`);
//! * **Vertex** colours, interpolated at the hit with its barycentrics
//!   (b0, b1, b2) = (1 − b1 − b2, b1, b2) (the G-buffer's, gbuffer.rs):
//!   `color · Σ b_i c(v_i)`;
//! * **Face** colours: `color · c(f)`, f the face hit;
//! * **Texture**: `color · T(u, v)`, (u, v) the vertices' UVs interpolated
//!   as the vertex colours are, T the base-colour image sampled bilinearly
//!   with the texture repeating (glTF's default wrap). The image holds 8-bit
//!   sRGB codes; each of the four texels read is decoded to linear
//!   reflectance first (IEC 61966-2-1: c/12.92 at or below 0.04045, else
//!   ((c + 0.055)/1.055)^2.4), then they are blended, as a GPU's sRGB
//!   texture units filter. Texel (i, j) (row i from the top) has its centre
//!   at (u, v) = ((j + ½)/W, 1 − (i + ½)/H): v points up the image, as
//!   trimesh gives glTF and OBJ UVs.
//!
//! Colours are linear RGB in [0, 1] (vertex and face colours arrive
//! decoded: python/softshadow/materials.py). A mesh without a material
//! takes the call's albedo (`albedo=`, or the default grey); an `albedo=`
//! the user gives overrides every material.

use super::gbuffer::{GBuffer, NO_FACE};
use crate::error::{Error, Result};
use crate::geom::mesh::MeshRef;
use rayon::prelude::*;

/// The largest texture, in texels (the light-view maps' limit).
pub const MAX_TEXTURE_TEXELS: usize = crate::geom::light::MAX_TEXELS;

/// What a material's colour varies with (module doc).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Varies<'a> {
    Constant,
    Vertex(&'a [[f32; 3]]),
    Face(&'a [[f32; 3]]),
    Texture {
        uv: &'a [[f32; 2]],
        /// Row-major, row 0 at the top: `width * height` sRGB codes.
        texels: &'a [[u8; 3]],
        width: usize,
        height: usize,
    },
}

/// A mesh's material: a linear colour factor and what multiplies it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material<'a> {
    pub color: [f64; 3],
    pub varies: Varies<'a>,
}

impl Material<'_> {
    /// Checks the material of `mesh` (named `arg`): the colour and every
    /// colour in [0, 1], one colour per vertex or face, one finite UV per
    /// vertex, a texture of `width * height` texels, at least one, at most
    /// `MAX_TEXTURE_TEXELS`.
    pub fn check(&self, arg: &str, mesh: &MeshRef) -> Result<()> {
        let unit = |c: &[f32; 3]| c.iter().all(|x| (0.0..=1.0).contains(x));
        if !self.color.iter().all(|x| (0.0..=1.0).contains(x)) {
            return Err(Error::invalid(
                arg,
                format!("colour must be in [0, 1], got {:?}", self.color),
            ));
        }
        let count = |what: &str, got: usize, want: usize| {
            if got == want {
                Ok(())
            } else {
                Err(Error::shape(
                    arg,
                    format!("{got} {what} for a mesh of {want}"),
                ))
            }
        };
        let colours = |c: &[[f32; 3]]| match c.iter().position(|c| !unit(c)) {
            None => Ok(()),
            Some(k) => Err(Error::invalid(
                arg,
                format!("colours must be in [0, 1], got {:?} at row {k}", c[k]),
            )),
        };
        match self.varies {
            Varies::Constant => Ok(()),
            Varies::Vertex(c) => {
                count("vertex colours", c.len(), mesh.vertices.len())?;
                colours(c)
            }
            Varies::Face(c) => {
                count("face colours", c.len(), mesh.faces.len())?;
                colours(c)
            }
            Varies::Texture {
                uv,
                texels,
                width,
                height,
            } => {
                count("UVs", uv.len(), mesh.vertices.len())?;
                if let Some(k) = uv.iter().position(|t| !t.iter().all(|x| x.is_finite())) {
                    return Err(Error::invalid(
                        arg,
                        format!("UVs must be finite, got {:?} at row {k}", uv[k]),
                    ));
                }
                let n = width.saturating_mul(height);
                if n == 0 || n > MAX_TEXTURE_TEXELS || n != texels.len() {
                    return Err(Error::invalid(
                        arg,
                        format!(
                            "texture must be 1 to {MAX_TEXTURE_TEXELS} texels of {width}x{height}, \
                             got {}",
                            texels.len()
                        ),
                    ));
                }
                Ok(())
            }
        }
    }
}

/// An sRGB-encoded value x in [0, 1] as linear reflectance, by the exact
/// transfer function of IEC 61966-2-1 (module doc); x clipped to [0, 1]
/// first (NaN gives 0). Python's `materials.srgb_to_linear` is this.
pub fn srgb_to_linear(x: f64) -> f64 {
    let x = if x > 0.0 { x.min(1.0) } else { 0.0 };
    if x <= 0.04045 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// The sRGB code c / 255 as linear reflectance.
fn decode(c: u8) -> f64 {
    srgb_to_linear(f64::from(c) / 255.0)
}

/// Every code decoded once.
fn decoded() -> [f32; 256] {
    std::array::from_fn(|c| decode(c as u8) as f32)
}

/// The texture at (u, v), bilinear in linear values, repeating.
fn sample(
    lut: &[f32; 256],
    texels: &[[u8; 3]],
    width: usize,
    height: usize,
    uv: [f64; 2],
) -> [f64; 3] {
    let x = uv[0] * width as f64 - 0.5;
    let y = (1.0 - uv[1]) * height as f64 - 0.5;
    let (x0, y0) = (x.floor(), y.floor());
    let (fx, fy) = (x - x0, y - y0);
    let wrap = |i: f64, n: usize| i.rem_euclid(n as f64) as usize % n;
    let (i0, i1) = (wrap(x0, width), wrap(x0 + 1.0, width));
    let (j0, j1) = (wrap(y0, height), wrap(y0 + 1.0, height));
    let at = |i: usize, j: usize, c: usize| f64::from(lut[texels[j * width + i][c] as usize]);
    std::array::from_fn(|c| {
        let top = at(i0, j0, c) * (1.0 - fx) + at(i1, j0, c) * fx;
        let bottom = at(i0, j1, c) * (1.0 - fx) + at(i1, j1, c) * fx;
        top * (1.0 - fy) + bottom * fy
    })
}

/// The albedo of every pixel of `g` (row-major, RGB; 0 where no surface):
/// its mesh's material where `materials` has one, else `per_mesh[mesh]`.
/// `meshes` are the call's (the faces the G-buffer's `face` indexes).
pub fn albedo_image(
    g: &GBuffer,
    meshes: &[MeshRef],
    per_mesh: &[[f64; 3]],
    materials: &[Option<Material>],
) -> Vec<[f32; 3]> {
    let lut = decoded();
    (0..g.len())
        .into_par_iter()
        .with_min_len(256)
        .map(|k| {
            let Ok(mesh) = usize::try_from(g.mesh_id[k]) else {
                return [0.0; 3];
            };
            let face = g.face[k];
            let Some(m) = materials
                .get(mesh)
                .copied()
                .flatten()
                .filter(|_| face != NO_FACE)
            else {
                return per_mesh[mesh].map(|c| c as f32);
            };
            let f = face as usize;
            let [b1, b2] = g.bary[k].map(f64::from);
            let b = [1.0 - b1 - b2, b1, b2];
            let corners = meshes[mesh].faces[f].map(|v| v as usize);
            let blend = |c: &[[f32; 3]]| -> [f64; 3] {
                std::array::from_fn(|ch| (0..3).map(|i| b[i] * f64::from(c[corners[i]][ch])).sum())
            };
            let base = match m.varies {
                Varies::Constant => [1.0; 3],
                Varies::Vertex(c) => blend(c),
                Varies::Face(c) => c[f].map(f64::from),
                Varies::Texture {
                    uv,
                    texels,
                    width,
                    height,
                } => {
                    let t: [f64; 2] = std::array::from_fn(|a| {
                        (0..3).map(|i| b[i] * f64::from(uv[corners[i]][a])).sum()
                    });
                    sample(&lut, texels, width, height, t)
                }
            };
            std::array::from_fn(|c| (m.color[c] * base[c]).clamp(0.0, 1.0) as f32)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_codes_decode_exactly() {
        assert_eq!(decode(0), 0.0);
        assert!((decode(255) - 1.0).abs() < 1e-15);
        assert!((decode(128) - 0.215_860_5).abs() < 1e-7);
        assert!((decode(10) - 10.0 / 255.0 / 12.92).abs() < 1e-15);
    }

    #[test]
    fn textures_are_bilinear_in_linear_values_and_repeat() {
        let lut = decoded();
        // 2 x 1: black, white.
        let texels = [[0u8; 3], [255u8; 3]];
        // Texel centres: u = 1/4 black, 3/4 white; halfway is the linear mean.
        let at = |u: f64| sample(&lut, &texels, 2, 1, [u, 0.5])[0];
        assert!(at(0.25).abs() < 1e-12);
        assert!((at(0.75) - 1.0).abs() < 1e-6);
        assert!((at(0.5) - 0.5).abs() < 1e-6);
        // Repeat: u and u + 1 agree; u = 0 blends the last and first texels.
        assert!((at(1.25) - at(0.25)).abs() < 1e-12);
        assert!((at(0.0) - 0.5).abs() < 1e-6);
        // v up: row 0 is the top (v near 1).
        let rows = [[255u8; 3], [0u8; 3]];
        assert!((sample(&lut, &rows, 1, 2, [0.5, 0.75])[0] - 1.0).abs() < 1e-6);
        assert!(sample(&lut, &rows, 1, 2, [0.5, 0.25])[0].abs() < 1e-12);
    }
}
