//! The public corpus (tests/corpus/models.toml): every model that is here compiles, verifies and
//! renders, as `tests/corpus/run` tables them. The committed models always run; the shared
//! scenes and the models a developer fetched run where present (the table says which are
//! absent). The render needs Vulkan (skipped without it, a failure under KILN_REQUIRE_VULKAN).

use kiln_test_support::vulkan;

#[test]
fn every_model_present_compiles_verifies_and_renders() {
    let entries = kiln_tests::corpus::entries().expect("tests/corpus/models.toml reads");
    assert!(entries.iter().filter(|e| e.root == "committed").count() >= 4, "the committed models are listed");
    let render = vulkan();
    let dir = tempfile::tempdir().unwrap();
    let rows: Vec<_> = entries.iter().map(|e| kiln_tests::corpus::run(e, dir.path(), render, &[])).collect();
    eprintln!("{}", kiln_tests::corpus::table(&rows));
    for r in &rows {
        if r.entry.root == "committed" {
            assert!(r.skipped.is_none(), "{}: a committed model is missing: {:?}", r.entry.name, r.skipped);
        }
        assert!(
            r.passed(),
            "{}: compile {:?}, verify {:?}, render {:?}",
            r.entry.name,
            r.compile,
            r.verify,
            r.render
        );
        if r.skipped.is_none() {
            assert!(r.triangles > 0, "{}: no triangles counted", r.entry.name);
        }
    }
}
