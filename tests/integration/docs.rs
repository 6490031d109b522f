//! The README and the guide name only what exists. Read as a newcomer follows them:
//! - every repository path they mention (a link or an image, or a path such as
//!   `src/sim/ripple.rs` in code or prose) is in the repository, and every `#anchor` they link
//!   to is a heading of the page it points into;
//! - every `--flag` given to a `tidepool` command (in a code block or an inline command, after
//!   `tidepool`, `cargo run ... --`, or a subcommand opening the code such as `render ocean`)
//!   is one that subcommand accepts, and so is every flag in a table under a heading that
//!   names a command (`` ### `tidepool render pool` flags ``); a flag quoted on its own
//!   (`` `--bandwidth` ``) is one some subcommand accepts.
//!
//! The flags are asked of the binary under test: `tidepool <subcommand> --help` lists them,
//! and a flag it does not list (a hidden old name) is tried as `tidepool <subcommand> --flag
//! --help --help`, which clap refuses with "unexpected argument" only when the flag is
//! unknown. Built without `serve`, the docs' `tidepool serve` commands fail the test, naming
//! the feature: the docs are checked whole or not at all.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use crate::common::tidepool;

/// The documents checked, from the repository's root.
const DOCUMENTS: &[&str] = &["README.md", "docs/GUIDE.md"];

/// A path that starts with one of these is a repository path.
const REPOSITORY_ROOTS: &[&str] =
    &["src/", "tests/", "docs/", "scripts/", "benches/", "examples/", "assets/", "fuzz/", ".ci/"];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// One piece of a document: its line number, the heading it is under, and whether it is code.
struct Piece<'a> {
    line: usize,
    heading: &'a str,
    text: &'a str,
    code: bool,
}

/// Splits a markdown document into prose and code pieces: each line of a fenced block is code,
/// and each `inline span` of the other lines is code too (the rest of the line is prose).
fn pieces(document: &str) -> Vec<Piece<'_>> {
    let mut out = Vec::new();
    let (mut fenced, mut heading) = (false, "");
    for (k, line) in document.lines().enumerate() {
        let number = k + 1;
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if fenced {
            out.push(Piece { line: number, heading, text: line, code: true });
            continue;
        }
        if line.starts_with('#') {
            heading = line;
        }
        for (i, part) in line.split('`').enumerate() {
            out.push(Piece { line: number, heading, text: part, code: i % 2 == 1 });
        }
    }
    out
}

/// GitHub's anchor for a heading: lower case, spaces to hyphens, punctuation other than `-`
/// and `_` dropped.
fn slug(heading: &str) -> String {
    let text = heading.trim_start_matches('#').trim();
    let mut out = String::new();
    for c in text.chars().flat_map(char::to_lowercase) {
        if c == ' ' {
            out.push('-');
        } else if c.is_alphanumeric() || c == '-' || c == '_' {
            out.push(c);
        }
    }
    out
}

/// The anchors of a markdown file (headings outside code blocks; repeats get `-1`, `-2`).
fn anchors(document: &str) -> BTreeSet<String> {
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    let mut out = BTreeSet::new();
    let mut fenced = false;
    for line in document.lines() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
        } else if !fenced && line.starts_with('#') {
            let base = slug(line);
            let n = seen.entry(base.clone()).or_insert(0);
            out.insert(if *n == 0 { base.clone() } else { format!("{base}-{n}") });
            *n += 1;
        }
    }
    out
}

/// `a/{b,c}.rs` is `a/b.rs` and `a/c.rs`.
fn expand_braces(path: &str) -> Vec<String> {
    match (path.find('{'), path.find('}')) {
        (Some(open), Some(close)) if open < close => path[open + 1..close]
            .split(',')
            .flat_map(|choice| expand_braces(&format!("{}{choice}{}", &path[..open], &path[close + 1..])))
            .collect(),
        _ => vec![path.to_string()],
    }
}

/// The repository paths a piece of text names: words that start with a repository root.
/// Placeholders (`<name>`, `*`, `{frame}`) are not paths.
fn repository_paths(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for word in text.split(|c: char| c.is_whitespace() || "`()[]\"'|;=".contains(c)) {
        let word = word.split('#').next().unwrap_or_default().trim_end_matches(['.', ',', ':', '!', '?']);
        let placeholder = word.contains(['<', '*', '…']) || word.contains("{frame");
        if placeholder || !REPOSITORY_ROOTS.iter().any(|r| word.starts_with(r)) {
            continue;
        }
        out.extend(expand_braces(word));
    }
    out
}

/// The targets of the markdown links and images in a line of prose: `[text](target)`.
fn link_targets(line: &str) -> Vec<&str> {
    line.match_indices("](")
        .filter_map(|(at, _)| {
            let rest = &line[at + 2..];
            let end = rest.find(')')?;
            let target = rest[..end].split_whitespace().next()?;
            Some(target)
        })
        .collect()
}

/// What `tidepool` accepts, asked of the binary under test and remembered.
#[derive(Default)]
struct Commands {
    /// The subcommands of each command path (`""` is `tidepool` itself).
    subcommands: BTreeMap<String, BTreeSet<String>>,
    /// The flags `--help` lists for each command path.
    flags: BTreeMap<String, BTreeSet<String>>,
    /// The outcome of trying a flag `--help` does not list, per (path, flag).
    tried: BTreeMap<(String, String), bool>,
}

impl Commands {
    /// Reads `tidepool <path> --help`, or says why it cannot.
    fn learn(&mut self, path: &str) -> Result<(), String> {
        if self.flags.contains_key(path) {
            return Ok(());
        }
        if path.starts_with("serve") && !cfg!(feature = "serve") {
            return Err(format!(
                "`tidepool {path}` is not in this build: the docs' serve flags are checked with `--features serve`, as the README's test command (`cargo test --all-features`) builds it"
            ));
        }
        let output = tidepool().args(path.split_whitespace()).arg("--help").output().expect("tidepool runs");
        let text = String::from_utf8_lossy(&output.stdout).into_owned();
        if !output.status.success() {
            return Err(format!("`tidepool {path}` is not a command"));
        }
        let (mut subcommands, mut flags, mut in_commands) = (BTreeSet::new(), BTreeSet::new(), false);
        for line in text.lines() {
            let trimmed = line.trim_start();
            if line.ends_with(':') && !line.starts_with(' ') {
                in_commands = line == "Commands:";
                continue;
            }
            if in_commands
                && line.starts_with("  ")
                && !line.starts_with("   ")
                && let Some(name) = trimmed.split_whitespace().next()
            {
                subcommands.insert(name.to_string());
            }
            if trimmed.starts_with('-') {
                // An option line: `-s, --size <WxH>`, `--no-shading`, `[aliases: --old]`.
                for word in trimmed.split(|c: char| c.is_whitespace() || "<>[],=".contains(c)) {
                    if word.starts_with("--") && word.len() > 2 {
                        flags.insert(word.to_string());
                    }
                }
            }
        }
        subcommands.remove("help");
        self.subcommands.insert(path.to_string(), subcommands);
        self.flags.insert(path.to_string(), flags);
        Ok(())
    }

    /// Whether `tidepool <path>` accepts `flag`.
    fn accepts(&mut self, path: &str, flag: &str) -> Result<bool, String> {
        self.learn(path)?;
        if self.flags[path].contains(flag) {
            return Ok(true);
        }
        let key = (path.to_string(), flag.to_string());
        if let Some(&known) = self.tried.get(&key) {
            return Ok(known);
        }
        // A flag --help does not list (hidden): clap refuses an unknown one before it reads
        // the help flags; a known one ends in the help (or in a missing value).
        let dir = tempfile::tempdir().unwrap();
        let output = tidepool()
            .current_dir(dir.path())
            .stdin(std::process::Stdio::null())
            .args(path.split_whitespace())
            .args([flag, "--help", "--help"])
            .output()
            .expect("tidepool runs");
        let stderr = String::from_utf8_lossy(&output.stderr);
        let known = !stderr.contains("unexpected argument");
        self.tried.insert(key, known);
        Ok(known)
    }

    /// The subcommand path that opens `words` (`["render", "pool", "--size", ...]` opens with
    /// `render pool`), and how many words it took.
    fn path_of(&mut self, words: &[&str]) -> Result<(String, usize), String> {
        let mut path = String::new();
        let mut taken = 0;
        for word in words {
            self.learn(&path)?;
            if !self.subcommands[&path].contains(*word) {
                break;
            }
            path = if path.is_empty() { word.to_string() } else { format!("{path} {word}") };
            taken += 1;
        }
        self.learn(&path)?;
        Ok((path, taken))
    }

    /// Every flag of every command, for flags quoted on their own.
    fn any_accepts(&mut self, flag: &str) -> Result<bool, String> {
        let mut stack = vec![String::new()];
        let mut paths = Vec::new();
        while let Some(path) = stack.pop() {
            self.learn(&path)?;
            for sub in self.subcommands[&path].clone() {
                stack.push(if path.is_empty() { sub } else { format!("{path} {sub}") });
            }
            paths.push(path);
        }
        for path in &paths {
            if self.accepts(path, flag)? {
                return Ok(true);
            }
        }
        Ok(false)
    }
}

/// Ends a command: a comment, a pipe, a redirection, a chain.
fn ends_command(word: &str) -> bool {
    word.starts_with('#')
        || ["|", "||", "&&", ";", ">", ">>", "2>", "<", "(", ")"].contains(&word)
        || word.starts_with("2>")
}

/// The `tidepool` commands in a line of code: the words after `tidepool` (or a path ending in
/// `/tidepool`), after `cargo run ... --` (unless it runs an example), or the whole line when
/// it opens with a subcommand (`render ocean --beaufort 6`), each up to where it ends.
fn commands_in<'a>(code: &'a str, subcommands: &BTreeSet<String>) -> Vec<Vec<&'a str>> {
    let words: Vec<&str> = code.split_whitespace().collect();
    let mut out = Vec::new();
    let take = |from: usize| words[from..].iter().take_while(|w| !ends_command(w)).copied().collect::<Vec<_>>();
    if words.first().is_some_and(|w| subcommands.contains(*w)) {
        out.push(take(0));
    }
    for (i, word) in words.iter().enumerate() {
        if *word == "tidepool" || word.ends_with("/tidepool") {
            out.push(take(i + 1));
        }
        if *word == "cargo" && words.get(i + 1) == Some(&"run") {
            let command = take(i + 2);
            let example = command.iter().any(|w| *w == "--example" || *w == "--bin");
            if let (Some(dashes), false) = (command.iter().position(|w| *w == "--"), example) {
                out.push(command[dashes + 1..].to_vec());
            }
        }
    }
    out
}

/// A `--flag` word's flag (`--size=1x1` is `--size`).
fn flag_of(word: &str) -> Option<&str> {
    let flag = word.split('=').next()?.trim_end_matches([',', '.', ':']);
    (flag.starts_with("--") && flag.len() > 2 && flag[2..].starts_with(|c: char| c.is_ascii_alphabetic()))
        .then_some(flag)
}

/// The command a heading names for the tables under it (`` ### `tidepool render ocean` flags ``).
fn command_of_heading(heading: &str) -> Option<Vec<&str>> {
    let inline = heading.split('`').nth(1)?;
    let words: Vec<&str> = inline.split_whitespace().collect();
    (words.first() == Some(&"tidepool")).then(|| words[1..].to_vec())
}

/// Every problem in one document, as `FILE:LINE: what`.
fn problems_in(name: &str, commands: &mut Commands) -> Vec<String> {
    let root = root();
    let path = root.join(name);
    let document = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
    let dir = path.parent().unwrap().to_path_buf();
    let mut problems = Vec::new();
    let mut say = |line: usize, what: String| problems.push(format!("{name}:{line}: {what}"));
    let own_anchors = anchors(&document);
    let top = match commands.learn("") {
        Ok(()) => commands.subcommands[""].clone(),
        Err(e) => return vec![format!("{name}: {e}")],
    };
    for piece in pieces(&document) {
        for p in repository_paths(piece.text) {
            if !root.join(p.trim_end_matches('/')).exists() {
                say(piece.line, format!("names `{p}`, which is not in the repository"));
            }
        }
        if !piece.code {
            for target in link_targets(piece.text) {
                check_link(target, &dir, &own_anchors, &mut |what| say(piece.line, what));
            }
            continue;
        }
        let mut in_command = BTreeSet::new();
        for command in commands_in(piece.text, &top) {
            if command.iter().any(|w| *w == "..." || *w == "…") {
                // `tidepool render ... --frames 300`: a placeholder for any subcommand.
                continue;
            }
            let (path, taken) = match commands.path_of(&command) {
                Ok(found) => found,
                Err(e) => {
                    say(piece.line, e);
                    continue;
                }
            };
            for word in &command[taken..] {
                let Some(flag) = flag_of(word) else { continue };
                in_command.insert(flag.to_string());
                match commands.accepts(&path, flag) {
                    Ok(true) => {}
                    Ok(false) => say(piece.line, format!("`tidepool {path}` has no flag `{flag}`")),
                    Err(e) => say(piece.line, e),
                }
            }
        }
        // A flag on its own: in a table under a heading that names a command, that command's;
        // anywhere else, some command's.
        let words: Vec<&str> = piece.text.split_whitespace().collect();
        let Some(flag) = words.first().and_then(|w| flag_of(w)) else { continue };
        if in_command.contains(flag) {
            continue;
        }
        let table_command =
            command_of_heading(piece.heading).filter(|_| is_first_cell(&document, piece.line, piece.text));
        let verdict = match table_command {
            Some(words) => commands.path_of(&words).and_then(|(path, _)| {
                commands.accepts(&path, flag).map(|ok| (!ok).then(|| format!("`tidepool {path}` has no flag `{flag}`")))
            }),
            None => {
                commands.any_accepts(flag).map(|ok| (!ok).then(|| format!("no tidepool command has a flag `{flag}`")))
            }
        };
        match verdict {
            Ok(None) => {}
            Ok(Some(what)) | Err(what) => say(piece.line, what),
        }
    }
    problems
}

/// Whether `span` is in the first cell of a table row at `line`.
fn is_first_cell(document: &str, line: usize, span: &str) -> bool {
    let text = document.lines().nth(line - 1).unwrap_or("");
    let mut cells = text.split('|');
    text.trim_start().starts_with('|') && cells.nth(1).is_some_and(|first| first.contains(&format!("`{span}`")))
}

/// Checks one link target: the file exists (relative to the document), and an anchor in it
/// (or in the document itself) is one of its headings.
fn check_link(target: &str, dir: &Path, own_anchors: &BTreeSet<String>, say: &mut dyn FnMut(String)) {
    if target.contains("://") || target.starts_with("mailto:") {
        return;
    }
    let (file, anchor) = match target.split_once('#') {
        Some((file, anchor)) => (file, Some(anchor)),
        None => (target, None),
    };
    let linked = dir.join(file);
    if !file.is_empty() && !linked.exists() {
        say(format!("links to `{target}`, which is not in the repository"));
        return;
    }
    let Some(anchor) = anchor else { return };
    let known = if file.is_empty() {
        own_anchors.clone()
    } else if file.ends_with(".md") {
        anchors(&std::fs::read_to_string(&linked).unwrap_or_default())
    } else {
        return;
    };
    if !known.contains(anchor) {
        say(format!("links to `{target}`, but no heading there has the anchor `#{anchor}`"));
    }
}

#[test]
fn the_readme_and_the_guide_name_only_paths_anchors_and_flags_that_exist() {
    let mut commands = Commands::default();
    let mut problems = Vec::new();
    for name in DOCUMENTS {
        problems.extend(problems_in(name, &mut commands));
    }
    problems.dedup();
    assert!(problems.is_empty(), "{} problems in the docs:\n{}", problems.len(), problems.join("\n"));
}

#[test]
fn the_checks_see_what_they_look_for() {
    assert_eq!(slug("### Why `--refraction auto`"), "why---refraction-auto");
    assert_eq!(slug("## Bytes on the wire: the link"), "bytes-on-the-wire-the-link");
    assert_eq!(
        repository_paths(
            "see `src/render/{lake,mirror}.rs` and docs/x.md#part, not ~/src/y or fuzz/artifacts/<target>/"
        ),
        ["src/render/lake.rs", "src/render/mirror.rs", "docs/x.md"]
    );
    assert_eq!(
        link_targets("![a](images/a.png) and [b](../SECURITY.md#threats)"),
        ["images/a.png", "../SECURITY.md#threats"]
    );
    let subcommands: BTreeSet<String> = ["render", "play"].map(String::from).into();
    assert_eq!(
        commands_in("tidepool play --record s.jsonl   # then: tidepool render pool --replay s.jsonl", &subcommands),
        [vec!["play", "--record", "s.jsonl"], vec!["render", "pool", "--replay", "s.jsonl"]]
    );
    assert_eq!(
        commands_in("cargo run --release -- render lake --wind 0 | head", &subcommands),
        [vec!["render", "lake", "--wind", "0"]]
    );
    assert!(commands_in("cargo run --release --example ocean_gallery -- docs/gallery", &subcommands).is_empty());
    assert_eq!(commands_in("render ocean --beaufort 3", &subcommands), [vec!["render", "ocean", "--beaufort", "3"]]);
    assert_eq!(flag_of("--size=1x1"), Some("--size"));
    assert_eq!(flag_of("--"), None);
    assert_eq!(command_of_heading("### `tidepool render pool` flags"), Some(vec!["render", "pool"]));
}
