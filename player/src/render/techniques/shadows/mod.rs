//! Shadows of the analytic lights.

use super::knobs::{Knob, UNBOUNDED, number, scene};
use super::techniques;

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

/// The `Technique` methods the traced shadow techniques share (their settings'
/// `light_radius` and `sun_degrees`): ray traced, falling back to the file's shadow maps (else
/// none), the shadow pass's layers accumulated and sized, the lights sized.
macro_rules! traced_shadows {
    () => {
        fn ray_traced(&self) -> bool {
            true
        }

        fn fallback(&self, shadow_maps: bool) -> Option<&'static str> {
            Some(if shadow_maps { "shadowmap" } else { "none" })
        }

        fn flags(&self) -> u32 {
            kiln_format::gpu::FrameFlags::RT_SHADOWS
        }

        fn accumulated(&self, lights: usize) -> Option<$crate::render::passes::rt_history::Accumulated> {
            use $crate::render::passes::rt_history::{Accumulated, Kind};
            use $crate::render::passes::rt_shadows::{SHADOWS, layers};
            let histories = ["rt shadows history a", "rt shadows history b"];
            Some(Accumulated::new(SHADOWS, histories, Kind::Layers, 1, layers(lights)))
        }

        fn rays(
            &self,
            scene: &$crate::render::techniques::RayScene,
            inputs: &mut $crate::render::techniques::RayInputs,
        ) {
            inputs.light_radius = self.light_radius;
            inputs.sun_degrees = self.sun_degrees;
            let layers = $crate::render::passes::rt_shadows::layers(scene.lights_used);
            inputs.rt.shadow_lights = layers.min(scene.lights_used as u32);
        }
    };
}
use traced_shadows;

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
