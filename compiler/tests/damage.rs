//! `kiln verify` on hundreds of randomly damaged copies of a real file: every one exits
//! non-zero with one line of error, and none panics.

#[path = "util/run.rs"]
mod run;

use run::kiln;

struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

#[test]
fn randomly_damaged_copies_are_all_refused() {
    let dir = tempfile::tempdir().unwrap();
    kiln(dir.path(), &["demo", "-o", "good.kiln", "-q"]).expect(0);
    let good = std::fs::read(dir.path().join("good.kiln")).unwrap();
    let mut rng = Rng(42);
    for case in 0..300 {
        let mut bad = good.clone();
        match case % 4 {
            0 => {
                let i = rng.below(bad.len());
                bad[i] ^= 1 << rng.below(8);
            }
            1 => bad.truncate(rng.below(good.len())),
            2 => {
                let start = rng.below(bad.len());
                let end = (start + 1 + rng.below(64)).min(bad.len());
                for b in &mut bad[start..end] {
                    *b = rng.next() as u8;
                }
                if bad == good {
                    bad[start] ^= 0xff;
                }
            }
            _ => {
                let i = rng.below(bad.len());
                bad.insert(i, rng.next() as u8);
            }
        }
        let name = format!("bad{case}.kiln");
        std::fs::write(dir.path().join(&name), &bad).unwrap();
        let run = kiln(dir.path(), &["verify", &name]);
        assert!(run.code == 1 || run.code == 3, "case {case}: {run:?}");
        assert!(!run.stderr.contains("panicked"), "case {case}: {run:?}");
        assert_eq!(run.stderr.lines().count(), 1, "case {case}: {run:?}");
        run.says("error: ");
        assert!(run.stdout.is_empty(), "case {case}: a refused file printed a report: {run:?}");
        std::fs::remove_file(dir.path().join(&name)).unwrap();
    }
}
