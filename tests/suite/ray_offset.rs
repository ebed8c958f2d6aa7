//! `offset_ray_origin` (crates/shading-core/src/ray_offset.rs) against an exact oracle: triangles at scales 1e-5 to
//! 1e5 and translated up to 1e5, points computed from barycentrics in f32 as the kernels do, the
//! plane evaluated in f64. The GLSL twin is checked against it in bvh_oracle
//! (`bvh_traversal_lights_and_camera_glsl_matches_rust`).

use glam::{DVec3, Vec3};
use restir_pt::gpu_types::{Triangle, NO_EMITTER};
use restir_pt::shading::bvh::intersect_triangle;
use restir_pt::shading::ray_offset::{offset_ray_origin, RAY_OFFSET_SCALE};

use crate::common::TestRng;

fn dvec(v: [f32; 3]) -> DVec3 {
    DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64)
}

/// A random triangle of size about `scale` around `center`, stored like the loader stores it
/// (vertex 0 and edges in f32), whose stored smallest angle is at least 3° (the bound of
/// crates/shading-core/src/ray_offset.rs); None where f32 cannot hold it (a triangle far smaller than its distance
/// from the origin collapses, which is why the loader re-centres scenes).
fn random_triangle(r: &mut TestRng, center: DVec3, scale: f64) -> Option<Triangle> {
    let v: Vec<DVec3> = (0..3).map(|_| center + scale * r.unit_vector().as_dvec3()).collect();
    let v0 = v[0].as_vec3();
    let tri = Triangle {
        v0: v0.into(),
        material: 0,
        e1: (v[1].as_vec3() - v0).into(),
        emitter: NO_EMITTER,
        e2: (v[2].as_vec3() - v0).into(),
        alpha_tested: 0,
    };
    let (e1, e2) = (dvec(tri.e1), dvec(tri.e2));
    let smallest = e1.angle_between(e2).min(e1.angle_between(e1 - e2)).min(e2.angle_between(e2 - e1));
    (smallest >= 3f64.to_radians()).then_some(tri)
}

#[test]
fn offset_ray_origin_clears_the_surface_at_every_scale_and_position_by_a_bounded_amount() {
    let mut r = TestRng(20);
    let mut rays = 0;
    for scale_exp in -5..=5 {
        let scale = 10f64.powi(scale_exp);
        for translation in [0.0, 1.0, 1e3, 1e5] {
            let mut tested = 0;
            for _ in 0..300 {
                let center = DVec3::new(translation, -0.5 * translation, 0.25 * translation) + scale * r.unit_vector().as_dvec3();
                let Some(tri) = random_triangle(&mut r, center, scale) else {
                    continue;
                };
                tested += 1;
                let (v0, e1, e2) = (dvec(tri.v0), dvec(tri.e1), dvec(tri.e2));
                let n64 = e1.cross(e2).normalize();
                let n = tri.normal_area2().normalize();
                let sum = Vec3::from(tri.v0).abs() + Vec3::from(tri.e1).abs() + Vec3::from(tri.e2).abs();
                for _ in 0..8 {
                    let (mut b1, mut b2) = (r.uniform(), r.uniform());
                    if b1 + b2 > 1.0 {
                        (b1, b2) = (1.0 - b1, 1.0 - b2);
                    }
                    // As the kernels compute a hit point.
                    let p = Vec3::from(tri.v0) + b1 * Vec3::from(tri.e1) + b2 * Vec3::from(tri.e2);
                    for side in [1.0f32, -1.0] {
                        let ns = n * side;
                        let o = offset_ray_origin(p, ns, &tri);
                        let height = (o.as_dvec3() - v0).dot(n64) * side as f64;
                        let bound = 2.0 * (RAY_OFFSET_SCALE * ns.abs().dot(sum)) as f64;
                        assert!(
                            height > 0.0 && height <= bound,
                            "scale {scale:e}, translation {translation:e}: origin {o} is {height:e} off the plane (bound {bound:e})"
                        );
                        // No ray into the side it leaves to may hit the triangle it leaves, down to
                        // grazing angles.
                        for k in 0..8 {
                            let mut d = r.unit_vector();
                            if d.dot(ns) < 0.0 {
                                d -= 2.0 * d.dot(ns) * ns;
                            }
                            if k == 0 {
                                d = (d - d.dot(ns) * ns).normalize() + 1e-3 * ns;
                            }
                            rays += 1;
                            assert!(
                                intersect_triangle(o, d.normalize(), &tri, 1e30).is_none(),
                                "scale {scale:e}, translation {translation:e}: a ray from {o} along {d} hits the triangle it leaves"
                            );
                        }
                    }
                }
            }
            // f32 holds the triangles unless they are below about 1e-4 of their distance from
            // the origin.
            assert!(
                tested >= 150 || scale < 1e-4 * translation,
                "scale {scale:e}, translation {translation:e}: {tested} triangles tested"
            );
        }
    }
    eprintln!("{rays} rays left their triangles cleanly");
}
