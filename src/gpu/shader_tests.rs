//! Checks that need no device: every WGSL module parses and validates with
//! naga (what wgpu runs on it), and every parameter struct shared by Rust and
//! WGSL has the same member offsets and sizes on both sides.

use super::exact::{ExactParams, SOURCE as EXACT_SOURCE};
use super::eye::{GpuRayStart, HitsParams, HITS_SOURCE, RAYS_SOURCE};
use super::gather::{
    module_source, ChunkParams, GatherParams, GpuGroup, GpuPoint, PointsParams, RowSpan, Variant,
    BITMASK_CLOSED_SOURCE, BITMASK_OPEN_SOURCE, BITMASK_SOURCE, GATHER_SOURCE, SSM_SOURCE,
};
use super::irradiance_weight::GpuWeighPoint;
use super::pcss::{Coord, GpuPcssPoint, PcssChunk, PcssParams, SOURCE as PCSS_SOURCE};
use super::raster::{FillParams, GpuTri, RasterParams, RasterTile, SOURCE as RASTER_SOURCE};
use super::shadow_mapping::{GpuBlurPixel, GpuSmPoint, GpuSmTri, SmParams, SOURCE as SM_SOURCE};
use super::smoothies::{
    GpuSmoothie, SmoothieChunk, SmoothieParams, TentAxis, TentPoint, SOURCE as SMOOTHIES_SOURCE,
};
use super::sphere_rays::{GpuSphereStart, SphereParams, SOURCE as SPHERE_SOURCE};

/// Every shader module the backend builds, by name.
fn modules() -> Vec<(String, String)> {
    let mut m: Vec<(String, String)> = vec![
        ("raster.wgsl".into(), RASTER_SOURCE.to_string()),
        ("exact.wgsl".into(), EXACT_SOURCE.to_string()),
        ("exact.wgsl + eye_hits.wgsl".into(), HITS_SOURCE.to_string()),
        ("exact.wgsl + eye_rays.wgsl".into(), RAYS_SOURCE.to_string()),
        (
            "exact.wgsl + sphere_rays.wgsl".into(),
            SPHERE_SOURCE.to_string(),
        ),
        ("smoothies.wgsl".into(), SMOOTHIES_SOURCE.to_string()),
        ("shadow_mapping.wgsl".into(), SM_SOURCE.to_string()),
        (
            "disk_overlap.wgsl + irradiance_weight.wgsl + pcss.wgsl".into(),
            PCSS_SOURCE.to_string(),
        ),
    ];
    // The occluder-map methods' modules: ssm and the four bitmask ones.
    m.extend(
        Variant::ALL
            .iter()
            .map(|v| (format!("gather.wgsl + {v:?}"), v.source())),
    );
    m
}

fn parse(name: &str, src: &str) -> naga::Module {
    naga::front::wgsl::parse_str(src)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(src)))
}

#[test]
fn every_wgsl_file_is_used_by_a_module() {
    // Files on disk beside this module: each must be part of a checked module.
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/src/gpu");
    let sources = [
        RASTER_SOURCE,
        GATHER_SOURCE,
        SSM_SOURCE,
        BITMASK_SOURCE,
        BITMASK_OPEN_SOURCE,
        BITMASK_CLOSED_SOURCE,
        EXACT_SOURCE,
        HITS_SOURCE,
        RAYS_SOURCE,
        SPHERE_SOURCE,
        SMOOTHIES_SOURCE,
        SM_SOURCE,
        PCSS_SOURCE,
    ];
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "wgsl") {
            let text = std::fs::read_to_string(&path).unwrap();
            assert!(
                sources.iter().any(|s| s.contains(text.as_str())),
                "{path:?} is not checked"
            );
        }
    }
}

#[test]
fn every_wgsl_module_parses_and_validates() {
    for (name, src) in modules() {
        let module = parse(&name, &src);
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&src)));
    }
}

#[test]
fn bitmask_modules_have_their_words_and_read_the_corners_only_with_closed_gaps() {
    use crate::methods::bitmask::Gaps;
    let mut indices = vec![];
    for v in Variant::ALL {
        indices.push(v.index());
        let Variant::Bitmask { words, gaps } = v else {
            continue;
        };
        let src = v.source();
        let module = parse(&format!("{v:?}"), &src);
        let info = naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        )
        .validate(&module)
        .unwrap();
        // The private mask holds WORDS / 4 vec4s.
        let (_, mask) = module
            .global_variables
            .iter()
            .find(|(_, g)| g.name.as_deref() == Some("mask"))
            .unwrap();
        match module.types[mask.ty].inner {
            naga::TypeInner::Array {
                size: naga::ArraySize::Constant(n),
                ..
            } => assert_eq!(n.get(), words / 4, "{v:?}"),
            ref t => panic!("{v:?}: mask is {t:?}"),
        }
        // Binding 13 (the corners) exists, and is read by row_stats and the
        // chunk entry points, only with closed gaps; never by the resolves.
        let corners = module
            .global_variables
            .iter()
            .find(|(_, g)| g.binding.as_ref().is_some_and(|b| b.binding == 13))
            .map(|(h, _)| h);
        assert_eq!(corners.is_some(), gaps == Gaps::Closed, "{v:?}");
        for (k, ep) in module.entry_points.iter().enumerate() {
            let reads = corners.is_some_and(|h| !info.get_entry_point(k)[h].is_empty());
            let should = gaps == Gaps::Closed
                && ["row_stats", "bitmask", "bitmask_points"].contains(&ep.name.as_str());
            assert_eq!(reads, should, "{v:?} {}", ep.name);
        }
    }
    indices.sort();
    assert_eq!(indices, (0..Variant::ALL.len()).collect::<Vec<_>>());
}

#[test]
fn mask_words_are_the_rank_tables_entries_and_cost_their_loop() {
    use super::gather::{mask_words, method_tables, texel_cost};
    use crate::methods::bitmask::{Gaps, SAMPLE_COUNTS};
    use crate::methods::{BitmaskKernel, Method};
    for samples in SAMPLE_COUNTS {
        for gaps in Gaps::ALL {
            let m = Method::Bitmask(BitmaskKernel {
                samples,
                hierarchy: false,
                gaps,
            });
            // method_tables asserts the length; the words hold every sample.
            let t =
                method_tables(m, crate::geom::light_shape::LightShape::rect([1.0, 1.0])).unwrap();
            let words = mask_words(samples) as usize;
            assert_eq!(t.len(), 2 * (samples as usize + 1) * words);
            assert!(32 * words >= samples as usize);
            // x_ge[0]: every sample.
            let all: u32 = t[..words].iter().map(|w| w.count_ones()).sum();
            assert_eq!(all, samples);
            assert_eq!(texel_cost(m), words / 4 + 1);
        }
    }
}

/// (member name, offset, size) of WGSL struct `name` in `module`, and its size.
fn wgsl_layout(module: &naga::Module, name: &str) -> (Vec<(String, u32, u32)>, u32) {
    let mut layouter = naga::proc::Layouter::default();
    layouter.update(module.to_ctx()).unwrap();
    for (_, ty) in module.types.iter() {
        if ty.name.as_deref() == Some(name) {
            if let naga::TypeInner::Struct { members, span } = &ty.inner {
                let m = members
                    .iter()
                    .map(|m| (m.name.clone().unwrap(), m.offset, layouter[m.ty].size))
                    .collect();
                return (m, *span);
            }
        }
    }
    panic!("struct {name} not found");
}

/// Rust's (member name, offset, size) for a #[repr(C)] struct.
macro_rules! rust_layout {
    ($t:ty { $($f:ident),* $(,)? }) => {{
        let v: Vec<(String, u32, u32)> = vec![$((
            stringify!($f).to_string(),
            std::mem::offset_of!($t, $f) as u32,
            {
                // Size of the field's type, from a zeroed value.
                let z: $t = bytemuck::Zeroable::zeroed();
                std::mem::size_of_val(&z.$f) as u32
            },
        )),*];
        (v, std::mem::size_of::<$t>() as u32)
    }};
}
pub(super) use rust_layout;

pub(super) fn assert_same(wgsl_src: &str, name: &str, rust: (Vec<(String, u32, u32)>, u32)) {
    let module = parse(name, wgsl_src);
    let wgsl = wgsl_layout(&module, name);
    assert_eq!(
        wgsl, rust,
        "{name}: WGSL (left) and Rust (right) layouts differ"
    );
}

#[test]
fn shared_structs_have_the_same_layout_in_rust_and_wgsl() {
    assert_same(
        &module_source(SSM_SOURCE),
        "WeighPoint",
        rust_layout!(GpuWeighPoint {
            p,
            valid,
            side,
            _pad
        }),
    );
    assert_same(
        RASTER_SOURCE,
        "RasterParams",
        rust_layout!(RasterParams {
            tile_count,
            width,
            height,
            out_offset,
            far_offset,
            prev_offset,
            peel_factor,
            _pad
        }),
    );
    assert_same(
        RASTER_SOURCE,
        "Tri",
        rust_layout!(GpuTri {
            x,
            y,
            i0,
            i1,
            j0,
            j1,
            w_ref,
            gx,
            gy
        }),
    );
    assert_same(
        RASTER_SOURCE,
        "Tile",
        rust_layout!(RasterTile {
            tri,
            i0,
            i1,
            j0,
            j1
        }),
    );
    assert_same(
        RASTER_SOURCE,
        "FillParams",
        rust_layout!(FillParams {
            offset,
            len,
            value,
            _pad
        }),
    );
    let gather = module_source(SSM_SOURCE);
    assert_same(
        &gather,
        "GatherParams",
        rust_layout!(GatherParams {
            rec_w,
            rec_h,
            occ_w,
            occ_h,
            n_layers,
            layer0_offset,
            layer_stride,
            ax_rec_x,
            ax_rec_y,
            ax_col_x0s,
            ax_row_y,
            samples,
            tx,
            ty,
            hw,
            hh,
            inv_half_lx,
            inv_half_ly,
            half_lx,
            half_ly,
            wx,
            rows_per_chunk,
            counted,
            disk
        }),
    );
    assert_same(
        &gather,
        "ChunkParams",
        rust_layout!(ChunkParams {
            layer,
            chunk,
            _pad0,
            _pad1
        }),
    );
    assert_same(
        &gather,
        "RowSpan",
        rust_layout!(RowSpan {
            w_max,
            first,
            last,
            _pad
        }),
    );
    assert_same(
        &gather,
        "PointsParams",
        rust_layout!(PointsParams {
            n_points,
            steps_per_chunk,
            chunks,
            weigh
        }),
    );
    assert_same(
        &gather,
        "GatherPoint",
        rust_layout!(GpuPoint { x, y, wr, live }),
    );
    assert_same(
        &gather,
        "GroupBounds",
        rust_layout!(GpuGroup {
            x_lo,
            x_hi,
            y_lo,
            y_hi,
            wr_min,
            live,
            _pad0,
            _pad1
        }),
    );
    assert_same(
        HITS_SOURCE,
        "HitsParams",
        rust_layout!(HitsParams {
            n,
            budget,
            _pad0,
            _pad1
        }),
    );
    assert_same(
        SPHERE_SOURCE,
        "SphereStart",
        rust_layout!(GpuSphereStart {
            ax,
            ay,
            az,
            valid,
            bx,
            by,
            bz,
            omc,
            nx,
            ny,
            nz,
            wx,
            wy,
            wz,
            e1x,
            e1y,
            e1z,
            e2x,
            e2y,
            e2z
        }),
    );
    assert_same(
        SPHERE_SOURCE,
        "SphereParams",
        rust_layout!(SphereParams {
            radius,
            _pad0,
            _pad1,
            _pad2
        }),
    );
    assert_same(
        RAYS_SOURCE,
        "RayStart",
        rust_layout!(GpuRayStart {
            ax,
            ay,
            az,
            valid,
            bx,
            by,
            bz,
            a0,
            au,
            av,
            _pad0,
            _pad1
        }),
    );
    assert_same(
        EXACT_SOURCE,
        "ExactParams",
        rust_layout!(ExactParams {
            rec_w,
            rec_h,
            chunk_start,
            chunk_len,
            light,
            budget,
            has_tris,
            t0,
            t1,
            ax_rec_x,
            ax_rec_y,
            _pad0,
            _pad1
        }),
    );
}

#[test]
fn smoothie_structs_have_the_same_layout_in_rust_and_wgsl() {
    assert_same(
        SMOOTHIES_SOURCE,
        "SmoothieParams",
        rust_layout!(SmoothieParams {
            occ_w,
            occ_h,
            rec_w,
            rec_h,
            rec_offset,
            front_offset,
            merge,
            tiles_x,
            t,
            falloff,
            per_chunk,
            _pad
        }),
    );
    assert_same(
        SMOOTHIES_SOURCE,
        "SmoothieChunk",
        rust_layout!(SmoothieChunk {
            chunk,
            _pad0,
            _pad1,
            _pad2
        }),
    );
    assert_same(
        SMOOTHIES_SOURCE,
        "Smoothie",
        rust_layout!(GpuSmoothie {
            kind,
            len,
            z0,
            z1,
            px,
            py,
            ax,
            ay,
            bx,
            by,
            _pad0,
            _pad1
        }),
    );
    assert_same(
        SMOOTHIES_SOURCE,
        "TentAxis",
        rust_layout!(TentAxis { a, b, w, _pad }),
    );
    assert_same(
        SMOOTHIES_SOURCE,
        "TentPoint",
        rust_layout!(TentPoint {
            ia,
            ib,
            ja,
            jb,
            wx,
            wy,
            z_aa,
            z_ba,
            z_ab,
            z_bb,
            live
        }),
    );
}

#[test]
fn shadow_mapping_structs_have_the_same_layout_in_rust_and_wgsl() {
    assert_same(
        SM_SOURCE,
        "SmParams",
        rust_layout!(SmParams {
            width,
            height,
            tiles_x,
            linear,
            two_layers,
            _pad0,
            chunk_start,
            chunk_len,
            work_offset,
            work_count,
            midpoint,
            pcf,
            n_points,
            img_w,
            img_h,
            inf_bits
        }),
    );
    assert_same(
        SM_SOURCE,
        "SmTri",
        rust_layout!(GpuSmTri {
            x,
            y,
            i0,
            i1,
            j0,
            j1,
            planes,
            k
        }),
    );
    assert_same(
        SM_SOURCE,
        "SmPoint",
        rust_layout!(GpuSmPoint {
            pixel,
            i,
            j,
            fx,
            fy,
            depth,
            gx,
            gy,
            ox,
            oy
        }),
    );
    assert_same(
        SM_SOURCE,
        "BlurPixel",
        rust_layout!(GpuBlurPixel {
            spacing,
            z,
            tol,
            surface
        }),
    );
}

#[test]
fn pcss_structs_have_the_same_layout_in_rust_and_wgsl() {
    assert_same(
        PCSS_SOURCE,
        "PcssParams",
        rust_layout!(PcssParams {
            n,
            mode,
            out_w,
            rec_offset,
            occ_w,
            occ_h,
            front_offset,
            front_len,
            taps,
            rows_per_chunk,
            half_per_w_x,
            half_per_w_y,
            disk,
            weigh,
            half_lx,
            half_ly
        }),
    );
    assert_same(
        PCSS_SOURCE,
        "PcssChunk",
        rust_layout!(PcssChunk {
            chunk,
            _pad0,
            _pad1,
            _pad2
        }),
    );
    assert_same(PCSS_SOURCE, "Coord", rust_layout!(Coord { base, frac }));
    assert_same(
        PCSS_SOURCE,
        "WeighPoint",
        rust_layout!(GpuWeighPoint {
            p,
            valid,
            side,
            _pad
        }),
    );
    assert_same(
        PCSS_SOURCE,
        "PcssPoint",
        rust_layout!(GpuPcssPoint {
            bx,
            fx,
            by,
            fy,
            z,
            live,
            pa,
            pb
        }),
    );
}
