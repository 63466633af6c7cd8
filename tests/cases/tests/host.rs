//! Runs the shared cases on the host; the QEMU image runs the same list on the Cortex-M4F.

#[test]
fn every_shared_case_passes_on_the_host() {
    let mut failures = Vec::new();
    let mut count = 0;
    for case in bowl_test_cases::all_cases() {
        count += 1;
        if let Err(f) = (case.run)() {
            failures.push(format!("{}: {:?}", case.name, f));
        }
    }
    assert!(count > 0, "no shared cases registered");
    assert!(
        failures.is_empty(),
        "{} of {count} shared cases failed:\n{}",
        failures.len(),
        failures.join("\n")
    );
}

#[test]
fn every_benchmark_input_gives_a_finite_value() {
    for bench in bowl_test_cases::all_benches() {
        assert!(bench.inputs > 0, "{} has no inputs", bench.name);
        for i in 0..bench.inputs {
            let v = (bench.run)(i);
            assert!(v.is_finite(), "{} input {i} gave {v}", bench.name);
        }
    }
}
