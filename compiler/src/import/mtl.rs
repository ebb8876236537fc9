//! MTL as real files write it, made into what `tobj` parses, and the texture statements' options.
//!
//! `tobj` fails a whole material library on one statement it cannot read (`Ka 0 0 0c` in
//! McGuire's `sportsCar.mtl` cost every material of the car), panics on some (`Kd 0.5`, which
//! the MTL specification allows: g and b default to r), and keeps non-finite values. [`sanitize`]
//! rewrites each statement into one `tobj` reads, or drops it with a warning naming the file and
//! line: a bad statement costs that statement, never the library.
//!
//! [`TextureStatement::parse`] reads a texture statement's options (`-clamp`, `-o`, `-s`, `-bm`
//! …) before its file name, which may contain spaces; what kiln cannot apply is warned about.

use kiln_format::manifest::Wrap;

/// MTL statements whose values are colours: `r [g b]` (g and b default to r).
const COLOURS: [&str; 5] = ["Ka", "Kd", "Ks", "Ke", "Tf"];
/// MTL statements whose value is one number.
const NUMBERS: [&str; 11] = ["Ns", "Ni", "d", "Tr", "Pr", "Pm", "Ps", "Pc", "Pcr", "aniso", "anisor"];
/// Texture statements: a file name after options. `tobj` fails the library on an empty one.
const TEXTURES: [&str; 14] = [
    "map_Ka", "map_Kd", "map_Ks", "map_Ke", "map_Ns", "map_ns", "map_NS", "map_d", "map_Bump", "map_bump",
    "bump", "norm", "disp", "decal",
];

/// `text` (the MTL file `file`) with every statement in a form `tobj` reads: colours of one
/// number widened to three, negative components clamped to 0, `illum 2.0` as `illum 2`, a
/// `newmtl` without a name named after its line; statements whose values are not finite numbers
/// of the count they need, and texture statements without a file, are dropped. Each change a
/// warning with the file and line.
pub fn sanitize(file: &str, text: &str, warnings: &mut Vec<String>) -> String {
    let mut out = String::with_capacity(text.len());
    for (i, line) in text.lines().enumerate() {
        // A dropped statement leaves its line empty: tobj's lines stay the file's.
        if let Some(s) = statement(line, file, i + 1, warnings) {
            out.push_str(&s);
        }
        out.push('\n');
    }
    out
}

/// Line `line_no` of `file` made readable (`None`: dropped, with a warning).
fn statement(line: &str, file: &str, line_no: usize, warnings: &mut Vec<String>) -> Option<String> {
    // Formatted only for a warning: most lines pass unchanged.
    let at = || format!("{file}:{line_no}");
    let mut words = line.split_whitespace();
    let key = words.next().unwrap_or_default();
    let values: Vec<&str> = words.collect();
    let number = |v: &str| v.parse::<f32>().ok().filter(|x| x.is_finite());
    let mut drop = |why: &str| {
        warnings.push(format!("{}: `{}` {why}; the statement is ignored", at(), line.trim()));
        None
    };
    if COLOURS.contains(&key) {
        let numbers: Vec<Option<f32>> = values.iter().map(|v| number(v)).collect();
        let mut rgb = match numbers.as_slice() {
            [Some(r)] => [*r; 3],
            [Some(r), Some(g), Some(b), ..] => [*r, *g, *b],
            _ if values.first().is_some_and(|v| *v == "spectral" || *v == "xyz") => {
                return drop("gives a spectral or CIE XYZ colour, which kiln does not read (give r g b)");
            }
            _ => return drop("needs one or three finite numbers (r, or r g b)"),
        };
        if rgb.iter().any(|&x| x < 0.0) {
            warnings.push(format!("{}: `{}` has a negative component; clamped to 0", at(), line.trim()));
            rgb = rgb.map(|x| x.max(0.0));
        }
        return Some(format!("{key} {} {} {}", rgb[0], rgb[1], rgb[2]));
    }
    if NUMBERS.contains(&key) {
        return match values.first().and_then(|v| number(v)) {
            Some(x) => Some(format!("{key} {x}")),
            None => drop("needs a finite number"),
        };
    }
    if key == "illum" {
        return match values.first().and_then(|v| number(v)) {
            Some(x) if x.fract() == 0.0 && (0.0..=10.0).contains(&x) => Some(format!("illum {}", x as u32)),
            _ => drop("needs an illumination model from 0 to 10"),
        };
    }
    if TEXTURES.contains(&key) {
        let parsed = TextureStatement::parse(&values.join(" "));
        return if parsed.name.is_empty() { drop("names no file") } else { Some(line.trim().to_string()) };
    }
    if key == "newmtl" && values.is_empty() {
        let name = format!("unnamed-{line_no}");
        warnings.push(format!("{}: `newmtl` without a name; named '{name}'", at()));
        return Some(format!("newmtl {name}"));
    }
    Some(line.to_string())
}

/// A texture statement's value: options, then the file name.
#[derive(Debug, Clone, PartialEq)]
pub struct TextureStatement {
    /// The file name (the words after the options, spaces kept).
    pub name: String,
    /// How the texture wraps: `-clamp on` clamps.
    pub wrap: Wrap,
    /// Options kiln reads but does not apply, each with why (for a warning).
    pub ignored: Vec<String>,
}

impl TextureStatement {
    /// Reads `value` (what follows `map_Kd` and the like). Options and their argument counts
    /// are the MTL specification's (Wavefront, "Options for texture map statements").
    pub fn parse(value: &str) -> TextureStatement {
        let words: Vec<&str> = value.split_whitespace().collect();
        let mut s = TextureStatement { name: String::new(), wrap: Wrap::Repeat, ignored: Vec::new() };
        let numeric = |w: &&str| w.parse::<f64>().is_ok();
        let mut i = 0;
        while i < words.len() && words[i].starts_with('-') {
            let option = words[i];
            i += 1;
            // `-o`, `-s`, `-t` take one to three numbers; the others a fixed count.
            let (args, default): (Vec<&str>, &[f64]) = match option {
                "-o" | "-s" | "-t" => {
                    let n = words[i..].iter().take(3).take_while(|w| numeric(w)).count();
                    let d: &[f64] = if option == "-s" { &[1.0, 1.0, 1.0] } else { &[0.0, 0.0, 0.0] };
                    (words[i..i + n].to_vec(), d)
                }
                "-mm" => (words[i..(i + 2).min(words.len())].to_vec(), &[0.0, 1.0]),
                "-bm" | "-boost" => (words[i..(i + 1).min(words.len())].to_vec(), &[1.0]),
                "-blendu" | "-blendv" | "-cc" | "-clamp" | "-texres" | "-imfchan" | "-type" => {
                    (words[i..(i + 1).min(words.len())].to_vec(), &[])
                }
                // Not an option: the name starts here (a file may be called `-1.png`).
                _ => {
                    i -= 1;
                    break;
                }
            };
            i += args.len();
            let is_default = !default.is_empty()
                && args.iter().zip(default).all(|(a, d)| a.parse::<f64>().is_ok_and(|a| a == *d));
            match option {
                "-clamp" => {
                    if args.first() == Some(&"on") {
                        s.wrap = Wrap::ClampToEdge;
                    }
                }
                // Blending across the seam and the texture's own resolution change nothing kiln
                // draws.
                "-blendu" | "-blendv" | "-texres" => {}
                _ if is_default => {}
                "-o" | "-s" => s.ignored.push(format!(
                    "{option} {} (texture {}) is not applied: the texture is sampled unmoved",
                    args.join(" "),
                    if option == "-o" { "offset" } else { "scale" }
                )),
                "-bm" => s.ignored.push(format!(
                    "-bm {} (bump multiplier) is not applied: the normal map keeps its strength",
                    args.join(" ")
                )),
                _ => s.ignored.push(format!("{option} {} is not applied", args.join(" "))),
            }
        }
        s.name = words[i.min(words.len())..].join(" ");
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn texture_options_come_before_a_name_with_spaces() {
        let t = TextureStatement::parse("-clamp on -o 0.5 0.25 -bm 1 my texture.png");
        assert_eq!(t.name, "my texture.png");
        assert_eq!(t.wrap, Wrap::ClampToEdge);
        assert_eq!(t.ignored.len(), 1, "{:?}", t.ignored);
        assert!(t.ignored[0].starts_with("-o 0.5 0.25"), "{:?}", t.ignored);
        let t = TextureStatement::parse("-s 1 1 1 -bm 0.3 -blendu off n.png");
        assert_eq!((t.name.as_str(), t.wrap), ("n.png", Wrap::Repeat));
        assert_eq!(t.ignored.len(), 1, "{:?}", t.ignored);
        assert!(t.ignored[0].starts_with("-bm 0.3"), "{:?}", t.ignored);
        // A name that starts with a minus sign and a number is a name.
        assert_eq!(TextureStatement::parse("-1.png").name, "-1.png");
        assert_eq!(TextureStatement::parse("-o 1").name, "");
    }

    #[test]
    fn statements_are_fixed_or_dropped_one_at_a_time() {
        let mut w = Vec::new();
        let text = "newmtl a\nKd 0.5\nKa 0 0 0c\nKs 1 -1 0.5\nillum 2.0\nillum x\nmap_Kd\nnewmtl\nKe spectral e.rfl\nNs 10\n";
        let out = sanitize("f.mtl", text, &mut w);
        let lines: Vec<&str> = out.lines().collect();
        assert_eq!(
            lines,
            [
                "newmtl a",
                "Kd 0.5 0.5 0.5",
                "",
                "Ks 1 0 0.5",
                "illum 2",
                "",
                "",
                "newmtl unnamed-8",
                "",
                "Ns 10"
            ]
        );
        assert_eq!(w.len(), 6, "{w:#?}");
        for (k, line) in [3, 4, 6, 7, 8, 9].iter().enumerate() {
            assert!(
                w.iter().any(|m| m.starts_with(&format!("f.mtl:{line}:"))),
                "warning {k} for line {line}: {w:#?}"
            );
        }
    }
}
