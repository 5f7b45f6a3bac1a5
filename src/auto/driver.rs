//! The planner's driver: a mesh call with a target framed once, its scene
//! measured (`measure.rs`), planned (`plan.rs`), and the planned config run
//! by the caller's `run` on the backend the call chose.

use super::measure::{layer_tries, scene_stats, thin_features};
use super::plan::{plan, Plan};
use crate::backend::Backend;
use crate::error::Result;
use crate::frame::{frame_scene, MapSettings, ShadowResult};
use crate::geom::light_space::LightSpace;
use crate::geom::mesh::MeshRef;
use crate::methods::config::CallContext;
use crate::methods::target::Target;
use crate::methods::MethodConfig;

/// A mesh call planned for `target` (`plan.rs`): the scene's stats,
/// the plan (after a timed probe for a time budget), for a union setting
/// what its occluders call for (`measure.rs`: thin features, the
/// layers tried on coarse maps); then the planned config resolved for the
/// backend and run. The planning time (the probe excluded) is the result's
/// "plan" stage.
pub(crate) fn planned(
    (occluders, receivers): (MeshRef, MeshRef),
    rule_method: &MethodConfig,
    space: &LightSpace,
    extent: Option<[f64; 2]>,
    ctx: &CallContext,
    target: &Target,
    run: impl Fn(&MethodConfig, bool, (usize, usize), Option<[f64; 2]>) -> Result<ShadowResult>,
) -> Result<(ShadowResult, MethodConfig, Option<Plan>)> {
    let t0 = std::time::Instant::now();
    // The framing every run starts from (its checks, transform and extent
    // fit), on the rule's settings; the planner reads its depth ranges.
    let (w, h) = ctx.resolution;
    let rule = MapSettings::new(w, h, extent, &rule_method.resolve(ctx)?);
    let framed = frame_scene(
        &occluders,
        &receivers,
        space,
        &rule,
        &mut crate::timing::Stopwatch::new(),
    )?;
    let stats = scene_stats(&framed, ctx.resolution);
    let mut p = plan(&stats, target, None);
    let mut probe = None;
    let mut probe_seconds = 0.0;
    if target.time.is_some() && !p.hard {
        // The probe: the cheapest soft setting, timed; kept when nothing
        // better fits the budget.
        let cfg = p.config.resolve(ctx)?;
        let t = std::time::Instant::now();
        let out = run(&cfg, false, (w, h), extent)?;
        probe_seconds = t.elapsed().as_secs_f64();
        p = plan(&stats, target, Some(t0.elapsed().as_secs_f64()));
        probe = Some((cfg, out));
    }
    // The GPU has no hard shadow map: the soft setting runs there.
    if p.hard && ctx.backend == Backend::Gpu {
        p.hard = false;
        if let Some(d) = p.decisions.iter_mut().find(|d| d.name == "hard") {
            d.taken = false;
            d.why
                .push_str("; the GPU backend has no hard shadow map, the soft setting runs");
        }
    }
    if let Some(c) = p.bitmask() {
        // The occluders as the union setting will read them
        // (`measure.rs`): thin features on the planned maps where
        // the target asks, the layers tried on coarse maps.
        use crate::geom::light::MapGrid;
        let occ = c.occluder_resolution.unwrap_or((w, h));
        let fitted = [framed.grid.tx, framed.grid.ty];
        let front = if p.thin_matters(target) {
            let grid = MapGrid::new(occ.0, occ.1, fitted)?;
            Some(thin_features(&framed, occluders.faces, &grid))
        } else {
            None
        };
        p.refine_thin(front, occ);
        let eighth = |n: usize| (n / 8).clamp(16.min(n), n);
        let quarter = |n: usize| (n / 4).clamp(64.min(n), n);
        let coarse = MapGrid::new(eighth(w), eighth(h), fitted)?;
        let coarse_occ = MapGrid::new(quarter(occ.0), quarter(occ.1), fitted)?;
        let kernel = |gaps| {
            MethodConfig::Bitmask(crate::methods::BitmaskConfig {
                samples: 256,
                passes: Some(2),
                occluder_resolution: Some((coarse_occ.width, coarse_occ.height)),
                gaps,
                // Without the hierarchy: at the coarse maps building its
                // levels costs more than it saves (bunny_floating, 32² x
                // 64²: 2.4 ms with, 1.0 ms without per try).
                hierarchy: Some(false),
            })
            .resolve(&CallContext {
                backend: Backend::Cpu,
                resolution: (coarse.width, coarse.height),
                ..*ctx
            })
            .map(|k| k.kernel())
        };
        use crate::methods::bitmask::Gaps;
        let tries = layer_tries(
            &framed,
            (occluders.faces, receivers.faces),
            (coarse, coarse_occ),
            (kernel(Gaps::Closed)?, kernel(Gaps::Open)?),
            crate::methods::config::MAX_PASSES,
        );
        p.set_layers(tries.passes, tries.surfaces, &tries.peeled, &tries.changes);
        // Only a plan that chose closed gaps may open them (a user's
        // Bitmask(gaps="open") never reaches the planner).
        p.set_gaps((c.gaps == Gaps::Closed).then_some(tries.gap_change));
    }
    drop(framed);
    let cfg = p.config.resolve(ctx)?;
    let planning = t0.elapsed().as_secs_f64() - probe_seconds;
    let mut out = match probe {
        Some((probe_cfg, out)) if probe_cfg == cfg => out,
        _ => run(&cfg, p.hard, (w, h), extent)?,
    };
    out.timings.insert(0, ("plan", planning));
    p.config = cfg;
    Ok((out, cfg, Some(p)))
}
