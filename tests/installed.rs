//! The program away from its source tree, as after `cargo install` or from the Debian
//! package: a copy of the binary in `PREFIX/bin`, run from an empty folder with an empty
//! home, lists and writes its demo scores and renders one with the motion database built
//! into it; a database in the user's data folder or in `PREFIX/share/timpanist` is found
//! before the built-in one (README "Installing").

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// A private prefix holding a copy of the binary, an empty home and an empty working folder.
struct Install {
    _dir: tempfile::TempDir,
    prefix: PathBuf,
    home: PathBuf,
    work: PathBuf,
}

impl Install {
    fn new() -> Install {
        let dir = tempfile::tempdir().unwrap();
        let prefix = dir.path().join("prefix");
        let (home, work) = (dir.path().join("home"), dir.path().join("work"));
        for d in [prefix.join("bin"), home.clone(), work.clone()] {
            std::fs::create_dir_all(d).unwrap();
        }
        std::fs::copy(
            env!("CARGO_BIN_EXE_timpanist"),
            prefix.join("bin/timpanist"),
        )
        .unwrap();
        Install {
            _dir: dir,
            prefix,
            home,
            work,
        }
    }

    /// Run the copied binary. A copy just written may be briefly "busy" (ETXTBSY): a
    /// process forked by another test thread while the copy was open holds it until that
    /// process execs; then the run is tried again.
    fn run(&self, args: &[&str]) -> Output {
        const TEXT_FILE_BUSY: i32 = 26;
        let mut tries = 0;
        loop {
            let result = Command::new(self.prefix.join("bin/timpanist"))
                .current_dir(&self.work)
                .env("HOME", &self.home)
                .env_remove("XDG_DATA_HOME")
                .env_remove("XDG_CONFIG_HOME")
                .args(args)
                .output();
            match result {
                Err(e) if e.raw_os_error() == Some(TEXT_FILE_BUSY) && tries < 50 => {
                    tries += 1;
                    std::thread::sleep(std::time::Duration::from_millis(20));
                }
                other => return other.unwrap(),
            }
        }
    }
}

fn text(out: &Output) -> String {
    format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    )
}

/// A database folder whose index is not RON, to see which folder the search picks.
fn broken_db(dir: &Path) {
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join("index.ron"), "not a database").unwrap();
}

#[test]
fn an_installed_binary_renders_a_demo_with_its_built_in_database() {
    let install = Install::new();
    let list = install.run(&["demos"]);
    assert!(list.status.success(), "{}", text(&list));
    assert!(text(&list).contains("improvisation"), "{}", text(&list));

    let written = install.run(&["demos", "--output", "demos"]);
    assert!(written.status.success(), "{}", text(&written));
    let again = install.run(&["demos", "--output", "demos"]);
    assert!(!again.status.success(), "demos overwrote existing scores");
    assert!(text(&again).contains("already exists"), "{}", text(&again));

    let out = install.run(&[
        "render",
        "demos/improvisation.ron",
        "--wav",
        "out.wav",
        "--stats",
    ]);
    assert!(out.status.success(), "{}", text(&out));
    assert!(
        text(&out).contains("database: the built-in synthetic database"),
        "{}",
        text(&out)
    );
    assert!(!text(&out).contains("not found"), "{}", text(&out));
    let wav = hound::WavReader::open(install.work.join("out.wav")).unwrap();
    assert!(wav.duration() > 48_000, "{} frames", wav.duration());
}

#[test]
fn installed_and_user_databases_come_before_the_built_in_one() {
    let install = Install::new();
    assert!(install.run(&["demos", "-o", "."]).status.success());
    let render = || install.run(&["render", "improvisation.ron", "--wav", "o.wav"]);

    let installed = install.prefix.join("share/timpanist/mocap");
    broken_db(&installed);
    let out = render();
    assert!(!out.status.success(), "{}", text(&out));
    assert!(
        text(&out).contains("share/timpanist/mocap/index.ron"),
        "{}",
        text(&out)
    );

    let user = install.home.join(".local/share/timpanist/mocap");
    broken_db(&user);
    let out = render();
    assert!(
        text(&out).contains(".local/share/timpanist/mocap/index.ron"),
        "{}",
        text(&out)
    );

    broken_db(&install.work.join("mocap"));
    let out = render();
    assert!(
        text(&out).contains("mocap/index.ron") && !text(&out).contains("share/timpanist"),
        "{}",
        text(&out)
    );
    assert!(
        !install.work.join("o.wav").exists(),
        "a failed render wrote its WAV"
    );
}
