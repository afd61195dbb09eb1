//! The floor plan of `src/`, read from the code: every top-level module sits on a floor,
//! and a module may name (`crate::…`) only modules on floors below its own, so no two
//! top-level modules import each other and nothing imports upward. Test modules
//! (`#[cfg(test)]`) and comments are not read. ARCHITECTURE.md explains the floors.

use std::fmt;
use std::path::{Path, PathBuf};

/// The floors, lowest first. A module on floor n imports only modules on floors < n.
const FLOORS: &[(&str, u8)] = &[
    ("base", 0),
    ("kit", 1),
    ("score", 2),
    ("body", 3),
    ("drum", 3),
    ("mocap", 4),
    ("sound", 4),
    ("motion", 5),
    ("transcribe", 5),
    ("render", 6),
    ("io", 6),
    ("scene", 6),
    ("exports", 7),
    ("app", 8),
    ("cli", 9),
];

fn floor(module: &str) -> Option<u8> {
    FLOORS.iter().find(|(m, _)| *m == module).map(|(_, f)| *f)
}

/// One import that breaks the floor plan.
#[derive(Debug, PartialEq)]
struct Violation {
    file: PathBuf,
    line: usize,
    from: String,
    to: String,
    text: String,
}

impl fmt::Display for Violation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let on = |m: &str| floor(m).map_or("no floor".to_string(), |f| format!("floor {f}"));
        write!(
            f,
            "{}:{}: `{}` ({}) imports `{}` ({}): {}",
            self.file.display(),
            self.line,
            self.from,
            on(&self.from),
            self.to,
            on(&self.to),
            self.text.trim()
        )
    }
}

/// `source` with comments and `#[cfg(test)]` items blanked out (newlines kept, so line
/// numbers stay right).
fn code_only(source: &str) -> String {
    let mut out: Vec<String> = source
        .lines()
        .map(|l| match l.find("//") {
            Some(i) => l[..i].to_string(),
            None => l.to_string(),
        })
        .collect();
    let mut i = 0;
    while i < out.len() {
        if out[i].trim() == "#[cfg(test)]" {
            // Blank the attribute and the item after it, up to its matching brace or `;`.
            let mut depth = 0i32;
            let mut opened = false;
            let mut j = i;
            while j < out.len() {
                let line = std::mem::take(&mut out[j]);
                for c in line.chars() {
                    match c {
                        '{' => {
                            depth += 1;
                            opened = true;
                        }
                        '}' => depth -= 1,
                        _ => {}
                    }
                }
                if (opened && depth <= 0) || (!opened && j > i && line.trim_end().ends_with(';')) {
                    break;
                }
                j += 1;
            }
            i = j;
        }
        i += 1;
    }
    out.join("\n")
}

/// The top-level modules a line names through `crate::`, also inside `crate::{a, b::c}`.
fn named_modules(line: &str) -> Vec<String> {
    let mut names = Vec::new();
    let mut rest = line;
    while let Some(i) = rest.find("crate::") {
        let after = &rest[i + "crate::".len()..];
        if let Some(group) = after.strip_prefix('{') {
            let mut depth = 0;
            let mut start = true;
            for (k, c) in group.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => break,
                    '}' => depth -= 1,
                    ',' if depth == 0 => start = true,
                    c if start && (c.is_alphanumeric() || c == '_') => {
                        let word: String = group[k..]
                            .chars()
                            .take_while(|c| c.is_alphanumeric() || *c == '_')
                            .collect();
                        names.push(word);
                        start = false;
                    }
                    c if c.is_whitespace() => {}
                    _ => start = false,
                }
            }
        } else {
            let word: String = after
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_')
                .collect();
            if !word.is_empty() {
                names.push(word);
            }
        }
        rest = after;
    }
    names
}

/// The floor-plan violations of one file of top-level module `module`.
fn violations_in(file: &Path, module: &str, source: &str) -> Vec<Violation> {
    let Some(own) = floor(module) else {
        return vec![Violation {
            file: file.to_path_buf(),
            line: 1,
            from: module.into(),
            to: module.into(),
            text: "a top-level module with no floor: add it to FLOORS and ARCHITECTURE.md".into(),
        }];
    };
    let mut found = Vec::new();
    for (n, line) in code_only(source).lines().enumerate() {
        for to in named_modules(line) {
            if to == module || to == "self" {
                continue;
            }
            let upward = floor(&to).is_none_or(|f| f >= own);
            if upward {
                found.push(Violation {
                    file: file.to_path_buf(),
                    line: n + 1,
                    from: module.into(),
                    to,
                    text: source.lines().nth(n).unwrap_or_default().into(),
                });
            }
        }
    }
    found
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Every violation in the crate's `src/` (lib.rs and main.rs name every module: skipped).
fn violations() -> Vec<Violation> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    files.sort();
    let mut found = Vec::new();
    for file in files {
        let rel = file.strip_prefix(&src).unwrap();
        let first = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy();
        let module = first.trim_end_matches(".rs").to_string();
        if module == "lib" || module == "main" {
            continue;
        }
        let source = std::fs::read_to_string(&file).unwrap();
        found.extend(violations_in(rel, &module, &source));
    }
    found
}

/// No module imports a module on its own floor or above (so no import cycle between
/// top-level modules); each offending line is named.
#[test]
fn every_import_points_down() {
    let found = violations();
    let report: Vec<String> = found.iter().map(ToString::to_string).collect();
    assert!(
        found.is_empty(),
        "imports against the floor plan:\n{}",
        report.join("\n")
    );
}

/// The checker catches an upward import, a grouped one and one on the same floor, and
/// ignores comments and test modules.
#[test]
fn the_checker_catches_an_injected_upward_import() {
    let source = "\
//! Kit docs naming crate::render::Rendering in a comment.
use crate::base::pitch::Pitch;
use crate::render::Rendering;
fn f() { let _ = crate::{score::Score, base::rng::Rng}; }
#[cfg(test)]
mod tests {
    use crate::app::EditorApp;
}
";
    let found = violations_in(Path::new("kit/mod.rs"), "kit", source);
    let named: Vec<(usize, &str)> = found.iter().map(|v| (v.line, v.to.as_str())).collect();
    assert_eq!(named, vec![(3, "render"), (4, "score")]);
    assert!(
        found[0]
            .to_string()
            .starts_with("kit/mod.rs:3: `kit` (floor 1) imports `render` (floor 6)")
    );

    let same_floor = violations_in(
        Path::new("body/sim.rs"),
        "body",
        "use crate::drum::DrumSet;",
    );
    assert_eq!(
        same_floor.len(),
        1,
        "body and drum share a floor: {same_floor:?}"
    );

    let unknown = violations_in(Path::new("extra.rs"), "extra", "");
    assert_eq!(unknown.len(), 1, "a module with no floor is reported");
}

/// Every module lib.rs declares has a floor.
#[test]
fn every_top_level_module_has_a_floor() {
    let lib =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("src/lib.rs")).unwrap();
    for line in code_only(&lib).lines() {
        if let Some(name) = line.trim().strip_prefix("pub mod ") {
            let name = name.trim_end_matches(';');
            assert!(
                floor(name).is_some(),
                "src/lib.rs declares `{name}` with no floor"
            );
        }
    }
}
