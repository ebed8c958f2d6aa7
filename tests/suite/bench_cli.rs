//! `restir-pt bench`: the stage times and CPU-time throughput of its report, and the kernel's
//! profile counters (`--counters`), whose totals follow from the traversal each scene uses.

use std::process::Command;

use crate::common::temp_file;

/// Runs a small counted bench on `scene` and returns its JSON report.
fn bench_report(scene: &str, name: &str) -> serde_json::Value {
    let report = temp_file(name, b"");
    let out = Command::new(env!("CARGO_BIN_EXE_restir-pt"))
        .args([
            "bench",
            scene,
            "--width",
            "24",
            "--height",
            "16",
            "--spp",
            "3",
            "--runs",
            "2",
            "--counters",
            "--validate",
        ])
        .arg("--report")
        .arg(&report)
        .current_dir(env!("CARGO_MANIFEST_DIR"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "bench failed: {stderr}");
    assert!(stderr.contains("whole process") && stderr.contains("node visits"), "{stderr}");
    serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap()
}

fn count(r: &serde_json::Value, key: &str) -> u64 {
    r["counters"][key].as_u64().unwrap_or_else(|| panic!("no counter {key}: {r}"))
}

#[test]
fn bench_reports_stages_cpu_time_and_traversal_counters() {
    let paths = 24 * 16 * 3 * 2;
    for (scene, triangles, brute_force) in [("scenes/cornell.gltf", 36, true), ("scenes/cornell-glossy.gltf", 1132, false)] {
        let r = bench_report(scene, &format!("bench-{triangles}.json"));
        assert_eq!(r["triangles"].as_u64(), Some(triangles));
        let stages = ["stage_load", "stage_device", "stage_warm_up", "stage_timed_runs"];
        let wall: f64 = stages.iter().map(|s| r[s]["wall_s"].as_f64().unwrap()).sum();
        let whole = r["whole_process"]["wall_s"].as_f64().unwrap();
        assert!(wall > 0.0 && wall <= whole, "stages {wall} s, whole process {whole} s");
        assert!(r["whole_process"]["cpu_s"].as_f64().unwrap() > 0.0);
        assert!(r["median_paths_per_cpu_second"].as_f64().unwrap() > 0.0);
        let lanes = count(&r, "subgroup_size");
        let traversals = count(&r, "traversals");
        // Every step traces one pair; a path takes at least one step and at most max depth + 1.
        assert!(
            traversals >= paths && traversals <= 9 * paths,
            "{traversals} traversals for {paths} paths"
        );
        assert_eq!(count(&r, "path_steps"), traversals);
        let tests = count(&r, "triangle_tests");
        assert!(
            tests <= count(&r, "triangle_iterations") * lanes,
            "more triangle tests than lanes ran"
        );
        if brute_force {
            assert_eq!(tests, triangles * traversals, "brute force tests every triangle once per pair");
            assert_eq!(count(&r, "node_visits"), 0);
        } else {
            let visits = count(&r, "node_visits");
            assert!(visits >= traversals && visits <= count(&r, "node_iterations") * lanes);
            assert!(
                tests > 0 && tests < triangles * traversals / 10,
                "{tests} tests: the BVH culls little"
            );
        }
    }
}
