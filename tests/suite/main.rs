//! The whole test suite in one binary (one link on 2 cores). GPU tests run on whatever Vulkan
//! device is present (lavapipe in CI) with the validation layer on; any message fails the test.

mod common;

mod bench_cli;
mod bsdf_oracle;
mod bvh_oracle;
mod candidates_oracle;
mod cli;
mod cli_behaviour;
mod cli_measurement;
mod dielectric_furnace;
mod furnace;
mod gris;
mod gris_oracle;
mod independent_renderer;
mod layout;
mod normal_mapped_scene;
mod punctual;
mod ray_offset;
mod real_scenes;
mod real_scenes_cli;
mod restir;
mod restir_unbiased;
mod rng_oracle;
mod robustness;
mod sampling_oracle;
mod sampling_statistics;
mod scale;
mod scale_invariance;
mod scene_limits_and_env;
mod scene_loader;
mod scene_sharing;
mod scenes;
mod shading_normal_scenes;
mod shading_normals;
mod shared_assets;
mod shift;
mod shift_oracle;
mod specular_layer;
mod speed_accuracy;
mod statistics;
mod surface_oracle;
mod sweeps;
mod textured_scenes;
mod trace_pair_oracle;
