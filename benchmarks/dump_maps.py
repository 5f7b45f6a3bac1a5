"""Writes the bunny's 256² light-view maps (two passes) and its light-space mesh
to /tmp, for the Rust kernel benches (ignored tests):

    python benchmarks/dump_maps.py
    cargo test --release --lib bench_ -- --ignored --nocapture --test-threads=1
"""

import numpy as np

import softshadow as ss
from softshadow import scenes

scene, light = scenes.bunny_floating()
sm = ss.soft_shadow_map(scene, light, resolution=256, passes=2)
sm.occluder_depth.tofile("/tmp/front.f32")
sm.occluder_depth_back.tofile("/tmp/back.f32")
sm.receiver_depth.tofile("/tmp/rec.f32")
v, f = scene.occluder_mesh
q = v - np.asarray(light.center)
np.column_stack([q @ light.u, q @ light.v, q @ light.n]).astype(np.float64).tofile("/tmp/bv.f64")
f.astype(np.uint32).tofile("/tmp/bf.u32")
print("extent", sm.extent)
