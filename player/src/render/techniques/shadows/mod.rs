//! Shadows of the analytic lights.

use super::knobs::{Knob, UNBOUNDED, number, scene};
use super::{RayInputs, RayScene, techniques};
use crate::render::passes::rt_history::{Accumulated, Kind};
use crate::render::passes::rt_shadows;

techniques! {
    /// Shadows of the analytic lights.
    Shadows for Shadows, default shadowmap::ShadowMap;
    none => Off,
    shadowmap => ShadowMap,
    rt => Rt,
    linespace => LineSpace,
}

/// The sphere radius of point and spot lights, for the traced shadow techniques.
pub const LIGHT_RADIUS: Knob = scene(number(
    "light-radius",
    "sphere radius of point and spot lights in scene units (0: hard shadows)",
    0.0,
    UNBOUNDED,
    0.0,
    &[0.0, 0.1, 1.0],
));

/// The angular diameter of directional lights, for the traced shadow techniques.
pub const SUN_ANGLE: Knob = scene(number(
    "sun-angle",
    "angular diameter of directional lights in degrees (the sun: 0.53)",
    0.0,
    179.99,
    0.0,
    &[0.0, 0.53, 2.0],
));

/// The lights' sizes and the shadow pass's layer count of a traced technique.
fn traced_rays(light_radius: f32, sun_degrees: f32, scene: &RayScene, inputs: &mut RayInputs) {
    inputs.light_radius = light_radius;
    inputs.sun_degrees = sun_degrees;
    inputs.rt.shadow_lights = rt_shadows::layers(scene.lights_used).min(scene.lights_used as u32);
}

/// The shadow layers the reprojected accumulation carries, one per light.
fn accumulated(lights: usize) -> Option<Accumulated> {
    let histories = ["rt shadows history a", "rt shadows history b"];
    Some(Accumulated::new(rt_shadows::SHADOWS, histories, Kind::Layers, 1, rt_shadows::layers(lights)))
}

/// What a traced technique falls back to: the file's shadow maps, else none.
fn traced_fallback(shadow_maps: bool) -> Option<&'static str> {
    Some(if shadow_maps { "shadowmap" } else { "none" })
}

impl Shadows {
    /// The light sizes of a traced technique (point/spot radius, sun degrees); `None` for the
    /// others.
    pub fn traced(&self) -> Option<(f32, f32)> {
        match *self {
            Shadows::Rt(rt::Rt { light_radius, sun_degrees })
            | Shadows::LineSpace(linespace::LineSpace { light_radius, sun_degrees, .. }) => {
                Some((light_radius, sun_degrees))
            }
            Shadows::Off(_) | Shadows::ShadowMap(_) => None,
        }
    }
}
