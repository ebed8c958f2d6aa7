//! The table of twins, checked without a device: each row is a GLSL function an oracle kernel
//! (glsl/oracle/) calls, its Rust twin of the same name and the oracle test that compares them,
//! whose body names the function. Conversely, every GLSL function of the twin folders
//! (glsl/shading_core/, glsl/shading/, glsl/scene/) with a Rust `fn` of the same name in the
//! mirrored crate is in the table, is called (through any chain of GLSL calls) by a function of
//! the table, whose oracle then compares it too, or is in [`NO_ORACLE`] with a reason. Text
//! scanning, not parsing: the GLSL of this repository defines functions at the start of a line.

use std::collections::BTreeMap;

use crate::common::{repo_path, repository_files};

/// (GLSL function, its file under glsl/, its Rust twin's file under the src/ of the crate that
/// the GLSL file's folder mirrors, the oracle test's file under tests/suite/, the oracle test).
#[rustfmt::skip]
const TWINS: &[(&str, &str, &str, &str, &str)] = &[
    ("pcg4d", "shading_core/rng.glsl", "rng.rs", "rng_oracle.rs", RNG),
    ("path_seed", "shading_core/rng.glsl", "rng.rs", "rng_oracle.rs", RNG),
    ("rng_uniform4", "shading_core/rng.glsl", "rng.rs", "rng_oracle.rs", RNG),
    ("build_onb", "shading_core/sampling.glsl", "sampling.rs", "sampling_oracle.rs", SAMPLING),
    ("to_local", "shading_core/sampling.glsl", "sampling.rs", "sampling_oracle.rs", SAMPLING),
    ("to_world", "shading_core/sampling.glsl", "sampling.rs", "sampling_oracle.rs", SAMPLING),
    ("sample_concentric_disk", "shading_core/sampling.glsl", "sampling.rs", "sampling_oracle.rs", SAMPLING),
    ("sample_cosine_hemisphere", "shading_core/sampling.glsl", "sampling.rs", "sampling_oracle.rs", SAMPLING),
    ("pdf_cosine_hemisphere", "shading_core/sampling.glsl", "sampling.rs", "sampling_oracle.rs", SAMPLING),
    ("sample_uniform_sphere", "shading_core/sampling.glsl", "sampling.rs", "sampling_oracle.rs", SAMPLING),
    ("sample_triangle", "shading_core/sampling.glsl", "sampling.rs", "sampling_oracle.rs", SAMPLING),
    ("sample_ggx_vndf", "shading_core/sampling.glsl", "sampling.rs", "sampling_oracle.rs", SAMPLING),
    ("power_heuristic", "shading_core/sampling.glsl", "sampling.rs", "sampling_oracle.rs", SAMPLING),
    ("bsdf_eval_pdf", "shading_core/bsdf.glsl", "bsdf.rs", "bsdf_oracle.rs", BSDF),
    ("bsdf_sample", "shading_core/bsdf.glsl", "bsdf.rs", "bsdf_oracle.rs", BSDF),
    ("trace_closest", "shading_core/bvh.glsl", "bvh.rs", "bvh_oracle.rs", SCENE),
    ("trace_occluded", "shading_core/bvh.glsl", "bvh.rs", "bvh_oracle.rs", SCENE),
    ("offset_ray_origin", "shading_core/ray_offset.glsl", "ray_offset.rs", "bvh_oracle.rs", SCENE),
    ("sample_light", "shading/lights.glsl", "lights.rs", "bvh_oracle.rs", SCENE),
    ("environment_pdf", "shading/lights.glsl", "lights.rs", "bvh_oracle.rs", SCENE),
    ("emitter_pdf", "shading/lights.glsl", "lights.rs", "bvh_oracle.rs", SCENE),
    ("light_select_pmf", "shading/light_tree.glsl", "light_tree.rs", "bvh_oracle.rs", SCENE),
    ("punctual_occluded", "shading/punctual.glsl", "lights.rs", "bvh_oracle.rs", SCENE),
    ("trace_pair", "shading_core/trace_pair.glsl", "bvh.rs", "trace_pair_oracle.rs", PAIR),
    ("bvh_traverse", "shading_core/alpha_trace.glsl", "alpha_trace.rs", "alpha_oracle.rs", ALPHA),
    ("trace_pair", "shading_core/alpha_trace_pair.glsl", "alpha_trace.rs", "alpha_oracle.rs", ALPHA),
    ("alpha_hash", "shading_core/alpha.glsl", "alpha.rs", "alpha_oracle.rs", ALPHA),
    ("alpha_keeps", "shading_core/alpha.glsl", "alpha.rs", "alpha_oracle.rs", ALPHA),
    ("material_alpha", "shading_core/texture.glsl", "texture.rs", "alpha_oracle.rs", ALPHA),
    ("surface_at", "shading_core/surface.glsl", "surface.rs", "surface_oracle.rs", SURFACE),
    ("triangle_bary", "shading_core/surface.glsl", "surface.rs", "surface_oracle.rs", SURFACE),
    ("texture_lookup", "shading_core/texture.glsl", "texture.rs", "surface_oracle.rs", SURFACE),
    ("texture_coordinates", "shading_core/texture.glsl", "texture.rs", "surface_oracle.rs", SURFACE),
    ("texture_tangent_frame", "shading_core/texture.glsl", "texture.rs", "surface_oracle.rs", SURFACE),
    ("textured_material", "shading_core/texture.glsl", "texture.rs", "surface_oracle.rs", SURFACE),
    ("normal_mapped", "shading_core/texture.glsl", "texture.rs", "surface_oracle.rs", SURFACE),
    ("shading_normal", "scene/hit_surface.glsl", "hit_surface.rs", "surface_oracle.rs", SURFACE),
    ("hit_shading", "scene/hit_surface.glsl", "hit_surface.rs", "surface_oracle.rs", SURFACE),
    ("mis_weight", "shading_core/gris.glsl", "gris.rs", "gris_oracle.rs", "gris_mis_weight_generalized_balance_glsl_matches_rust"),
    ("resampler_begin", "shading_core/reservoir.glsl", "gris.rs", "gris_oracle.rs", "gris_resampler_glsl_matches_rust"),
    ("resampler_finish", "shading_core/reservoir.glsl", "gris.rs", "gris_oracle.rs", "gris_resampler_glsl_matches_rust"),
    ("stream_path_candidates", "shading/candidates.glsl", "candidates.rs", "candidates_oracle.rs", CANDIDATES),
    ("shift_reconnection", "shading/shift.glsl", "shift/mod.rs", "shift_oracle.rs", "shift_reconnection_glsl_matches_rust"),
    ("shift_random_replay", "shading/shift.glsl", "shift/mod.rs", "shift_oracle.rs", "shift_random_replay_glsl_matches_rust"),
    ("shift_hybrid", "shading/shift.glsl", "shift/mod.rs", "shift_oracle.rs", "shift_hybrid_glsl_matches_rust"),
    ("inverse_reconnection", "shading/shift.glsl", "shift/mod.rs", "shift_oracle.rs", "inverse_reconnection_glsl_matches_rust"),
    ("inverse_random_replay", "shading/shift.glsl", "shift/mod.rs", "shift_oracle.rs", "inverse_random_replay_glsl_matches_rust"),
    ("inverse_hybrid", "shading/shift.glsl", "shift/mod.rs", "shift_oracle.rs", "inverse_hybrid_glsl_matches_rust"),
    ("resample_inputs", "shading/resample_inputs.glsl", "resample_inputs.rs", "reuse_oracle.rs", REUSE),
];

const RNG: &str = "rng_pcg4d_path_seed_rng_uniform4_glsl_matches_rust_bit_exact";
const SAMPLING: &str = "sampling_glsl_matches_rust";
const BSDF: &str = "bsdf_eval_pdf_and_bsdf_sample_glsl_matches_rust";
const SCENE: &str = "bvh_traversal_lights_and_camera_glsl_matches_rust";
const PAIR: &str = "trace_pair_glsl_matches_rust_bvh_and_brute_force";
const ALPHA: &str = "alpha_traversal_glsl_matches_rust";
const SURFACE: &str = "surface_at_texture_lookup_textured_material_normal_mapped_glsl_matches_rust";
const CANDIDATES: &str = "stream_path_candidates_glsl_matches_rust";
const REUSE: &str = "resample_inputs_generalized_balance_glsl_matches_rust";

/// (GLSL function, its file under glsl/, why no oracle compares it): twins of the same name that
/// no kernel reaches from the table.
const NO_ORACLE: &[(&str, &str, &str)] = &[(
    "ggx_vndf_pdf",
    "shading_core/bsdf.glsl",
    "no kernel calls it (bsdf_eval_pdf writes the VNDF pdf out); its Rust twin is checked against sampling by sampling_statistics.rs",
)];

/// The twin folders under glsl/ and the crates they mirror.
const MIRRORS: &[(&str, &str)] = &[("shading_core", "shading-core"), ("shading", "shading"), ("scene", "scene")];

fn read(relative: &str) -> String {
    let path = repo_path(relative);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// `text` without `//` and `/* */` comments, so that braces and parentheses in them do not count.
fn strip_comments(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(i) = rest.find('/') {
        out.push_str(&rest[..i]);
        let tail = &rest[i..];
        rest = if tail.starts_with("//") {
            &tail[tail.find('\n').unwrap_or(tail.len())..]
        } else if let Some(block) = tail.strip_prefix("/*") {
            &block[block.find("*/").map_or(block.len(), |j| j + 2)..]
        } else {
            out.push('/');
            &tail[1..]
        };
    }
    out + rest
}

/// The end (exclusive) of the bracketed group opening at `start` (`open` at `text[start]`).
fn close_of(text: &str, start: usize, open: u8, close: u8) -> usize {
    let mut depth = 0;
    for (i, &c) in text.as_bytes().iter().enumerate().skip(start) {
        depth += i32::from(c == open) - i32::from(c == close);
        if depth == 0 {
            return i + 1;
        }
    }
    text.len()
}

/// The functions a GLSL file defines (a prototype is no definition), each with its body.
fn glsl_definitions(source: &str) -> Vec<(String, String)> {
    let text = strip_comments(source);
    let mut found = Vec::new();
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let start = offset;
        offset += line.len();
        let words: Vec<&str> = line.split('(').next().unwrap_or("").split_whitespace().collect();
        let is_ident = |w: &str| w.chars().all(|c| c.is_ascii_alphanumeric() || c == '_');
        if !line.starts_with(|c: char| c.is_ascii_alphabetic())
            || !line.contains('(')
            || words.len() != 2
            || !words.iter().all(|w| is_ident(w))
        {
            continue;
        }
        let params_end = close_of(&text, start + line.find('(').expect("has '('"), b'(', b')');
        let after = text[params_end..].trim_start();
        if after.starts_with('{') {
            let body_start = text.len() - after.len();
            found.push((
                words[1].to_string(),
                text[body_start..close_of(&text, body_start, b'{', b'}')].to_string(),
            ));
        }
    }
    found
}

/// Where `text` holds `word` with no identifier character on either side: the text after it.
fn occurrences<'a>(text: &'a str, word: &'a str) -> impl Iterator<Item = &'a str> + 'a {
    let ident = |c: Option<char>| c.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_');
    text.match_indices(word)
        .filter(move |&(i, _)| !ident(text[..i].chars().next_back()) && !ident(text[i + word.len()..].chars().next()))
        .map(move |(i, _)| &text[i + word.len()..])
}

fn names(text: &str, word: &str) -> bool {
    occurrences(text, word).next().is_some()
}

fn calls(body: &str, function: &str) -> bool {
    occurrences(body, function).any(|after| after.trim_start().starts_with('('))
}

fn defines_rust_fn(source: &str, name: &str) -> bool {
    source
        .match_indices(&format!("fn {name}"))
        .any(|(i, m)| matches!(source[i + m.len()..].chars().next(), Some('(' | '<')))
}

/// The body of the test function `name` in `source`: to the first `}` at the start of a line.
fn test_body<'a>(source: &'a str, name: &str) -> Option<&'a str> {
    let start = source.find(&format!("\nfn {name}()"))?;
    let rest = &source[start + 1..];
    Some(&rest[..rest.find("\n}").unwrap_or(rest.len())])
}

#[test]
fn twins_table_rows_name_glsl_rust_and_oracle_test() {
    for &(name, glsl, rust, test_file, test) in TWINS {
        let row = format!("{name} ({glsl}, {rust}, {test_file} {test})");
        let definitions = glsl_definitions(&read(&format!("glsl/{glsl}")));
        assert!(definitions.iter().any(|(n, _)| n == name), "{row}: no GLSL definition");
        let krate = MIRRORS
            .iter()
            .find(|(folder, _)| glsl.starts_with(&format!("{folder}/")))
            .map_or("?", |m| m.1);
        let rust_file = format!("crates/{krate}/src/{rust}");
        assert!(defines_rust_fn(&read(&rust_file), name), "{row}: no `fn {name}` in {rust_file}");
        let source = read(&format!("tests/suite/{test_file}"));
        let body = test_body(&source, test).unwrap_or_else(|| panic!("{row}: no test `{test}`"));
        assert!(
            source[..source.find(body).unwrap_or(0)].trim_end().ends_with("#[test]"),
            "{row}: `{test}` is not a #[test]"
        );
        assert!(names(body, name), "{row}: the test's body does not name `{name}`");
    }
}

#[test]
fn twins_every_same_named_pair_is_in_the_table_or_compared_through_it() {
    let mut definitions: BTreeMap<String, Vec<String>> = BTreeMap::new();
    let mut pairs = Vec::new();
    for &(folder, krate) in MIRRORS {
        let rust: String = repository_files(&format!("crates/{krate}/src"), "rs")
            .iter()
            .map(|f| read(f))
            .collect();
        for file in repository_files(&format!("glsl/{folder}"), "glsl") {
            let file = file.strip_prefix("glsl/").expect("under glsl/").to_string();
            for (name, body) in glsl_definitions(&read(&format!("glsl/{file}"))) {
                if defines_rust_fn(&rust, &name) {
                    pairs.push((name.clone(), file.clone()));
                }
                definitions.entry(name).or_default().push(body);
            }
        }
    }
    // The functions an oracle compares: the table's, and every one they call.
    let mut compared: Vec<String> = TWINS.iter().map(|row| row.0.to_string()).collect();
    let mut i = 0;
    while i < compared.len() {
        for body in definitions.get(&compared[i]).into_iter().flatten() {
            for callee in definitions.keys() {
                if !compared.contains(callee) && calls(body, callee) {
                    compared.push(callee.clone());
                }
            }
        }
        i += 1;
    }
    assert!(
        pairs.len() > TWINS.len(),
        "only {} twin pairs found: the scan is broken",
        pairs.len()
    );
    for (name, file) in &pairs {
        let tabled = TWINS.iter().any(|row| row.0 == name && row.1 == file);
        let excused = NO_ORACLE.iter().any(|row| row.0 == name && row.1 == file);
        assert!(
            tabled || excused || compared.contains(name),
            "GLSL `{name}` (glsl/{file}) has a Rust twin but no oracle test compares it: add it to TWINS or NO_ORACLE"
        );
        assert!(
            !(excused && compared.contains(name)),
            "`{name}` is compared: remove it from NO_ORACLE"
        );
    }
    for (name, file, _) in NO_ORACLE {
        assert!(
            pairs.iter().any(|p| p.0 == *name && p.1 == *file),
            "NO_ORACLE: `{name}` (glsl/{file}) is no pair"
        );
    }
}
