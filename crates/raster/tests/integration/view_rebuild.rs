//! A moved camera in `mirrorbox view` builds its frame again from the device's cached
//! pipelines and the previous frame's targets (`build_planned_reusing`, `state_cache`):
//! nothing is compiled again, and the image is the one a fresh `render` of the new view
//! on a device of its own draws, bit for bit, for every registered method.

use glam::Vec3;
use mirrorbox_raster::{
    Gpu, METHODS, Method, RasterError, RenderSettings, build_planned, build_planned_reusing,
    plan_frame, render,
};
use mirrorbox_scene::Scene;

fn view(camera_shift: Vec3) -> Scene {
    let mut s = mirrorbox_scene::load::bundled_scene("mirror_box.json");
    s.camera = s.camera.with_size(96, 54);
    s.camera.position += camera_shift;
    s.camera.look_at += 0.5 * camera_shift;
    s
}

#[test]
fn a_moved_camera_compiles_nothing_again_and_draws_what_render_draws() {
    let gpu = Gpu::new().unwrap();
    let reference = Gpu::new().unwrap();
    let (a, b) = (view(Vec3::ZERO), view(Vec3::new(0.15, 0.05, -0.1)));
    let mut checked = 0;
    for entry in METHODS {
        let settings = RenderSettings {
            warmup: 0,
            ..RenderSettings::new(Method::defaults(entry))
        };
        let first = match plan_frame(&a, &settings)
            .map_err(RasterError::from)
            .and_then(|p| build_planned(&gpu, &a, p, &settings))
        {
            Ok(built) => built,
            // Only `ray-query`, only on an adapter without ray queries.
            Err(RasterError::MissingFeature { .. })
                if entry.name == "ray-query" && !gpu.report.ray_query =>
            {
                continue;
            }
            Err(e) => panic!("{}: {e}", entry.name),
        };
        first.draw(&gpu).unwrap();
        let output = first.output().clone();
        let before = gpu.states.counts();
        let planned = plan_frame(&b, &settings).unwrap();
        let moved = build_planned_reusing(&gpu, &b, planned, &settings, Some(first)).unwrap();
        let after = gpu.states.counts();
        assert_eq!(
            after.made, before.made,
            "{}: the moved camera's frame made pipeline state again",
            entry.name
        );
        assert!(after.reused > before.reused, "{}", entry.name);
        assert!(
            moved.output() == &output,
            "{}: the render target was not kept",
            entry.name
        );
        moved.draw(&gpu).unwrap();
        let image = moved.read_image(&gpu).unwrap();
        // On a device of its own: a cache key that wrongly matched another pipeline would
        // draw the same wrong image on the same device.
        let fresh = render(&reference, &b, &settings).unwrap().image;
        assert!(
            image.pixels == fresh.pixels,
            "{}: the rebuilt frame differs from a fresh render of the view",
            entry.name
        );
        let unmoved = render(&reference, &a, &settings).unwrap().image;
        assert!(
            unmoved.pixels != fresh.pixels,
            "{}: the camera did not move the image",
            entry.name
        );
        checked += 1;
    }
    let skipped = usize::from(!gpu.report.ray_query);
    assert_eq!(checked, METHODS.len() - skipped, "methods checked");
}
