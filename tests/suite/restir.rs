//! ReSTIR PT on the GPU against the path tracer.

use std::sync::atomic::AtomicBool;

use restir_pt::render::{PathTracer, RenderSettings, Restir, RestirSettings};
use restir_pt::scene::load_scene;

use crate::common::{assert_clean, gpu, repo_path};

#[test]
fn restir_smoke() {
    let ctx = gpu();
    let scene = load_scene(&repo_path("scenes/cornell.gltf")).unwrap();
    let settings = RenderSettings {
        width: 32,
        height: 32,
        spp: 2048,
        max_depth: 5,
        russian_roulette: false,
        ..Default::default()
    };
    let mut pt = PathTracer::new(&ctx, &scene, &settings).unwrap();
    pt.render(&|_| {}, &AtomicBool::new(false)).unwrap();
    let reference = pt.image().unwrap();
    let mean = |img: &restir_pt::render::Image| {
        let m = img.mean.iter().map(|v| v.x + v.y + v.z).sum::<f32>() / img.mean.len() as f32;
        let var = img.variance.iter().map(|v| v.x + v.y + v.z).sum::<f32>() / (img.mean.len() * img.mean.len()) as f32;
        (m, var.sqrt())
    };
    println!("pt mean {:?}", mean(&reference));
    for (temporal, spatial) in [(false, 0)] {
        let rs = RestirSettings { temporal, spatial, ..Default::default() };
        let mut r = Restir::new(&ctx, &scene, &settings, &rs).unwrap();
        let mut last = None;
        for _ in 0..1024 {
            last = Some(r.frame(&scene, 0, true).unwrap());
        }
        println!("temporal {temporal} spatial {spatial}: restir mean {:?} {:?}", mean(&r.image().unwrap()), last.unwrap().counters);
    }
    assert_clean(&ctx);
}
