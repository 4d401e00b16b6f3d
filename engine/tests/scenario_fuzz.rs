//! No input makes the scenario loader panic: random bytes, random TOML-like text and random
//! mutations of the shipped scenarios either load or give diagnostics placed inside the file.
//! Nor the sweep plan reader: mutations of the shipped plans are read or refused with a
//! message, and a plan read expands into as many runs as it counts, each with its own id.

use std::collections::BTreeSet;
use std::path::Path;

use proptest::prelude::*;
use uavex_engine::scenario::{ScenarioErrors, load, parse_str};
use uavex_engine::sweep::expand::expand;
use uavex_engine::sweep::plan::Plan;

const SHIPPED: &[&str] = &[
    include_str!("../../scenarios/eaae_pillars.toml"),
    include_str!("../../scenarios/eaae_simple.toml"),
    include_str!("../../scenarios/pillars_scripted.toml"),
    include_str!("../../scenarios/examples/all_obstacles.toml"),
    include_str!("../../scenarios/examples/lidar.toml"),
];

const SHIPPED_PLANS: &[&str] = &[
    include_str!("../../scenarios/eaae_protocol.toml"),
    include_str!("../../scenarios/tour_comparison.toml"),
    include_str!("../../scenarios/standoff_comparison.toml"),
    include_str!("../../scenarios/wide_camera_comparison.toml"),
    include_str!("../../docs/sweep_demo.toml"),
    include_str!("../../pgo/training.toml"),
];

/// Every diagnostic is inside the text: line 1 ..= lines + 1, column from 1.
fn assert_placed(text: &str, errors: &ScenarioErrors) {
    assert!(
        !errors.diagnostics.is_empty(),
        "an error without diagnostics"
    );
    let lines = text.lines().count() + 1;
    for d in &errors.diagnostics {
        assert!(
            d.line >= 1 && d.line <= lines && d.column >= 1,
            "misplaced diagnostic {d} in a text of {lines} lines"
        );
        assert!(!d.message.is_empty());
    }
}

fn check_text(text: &str) {
    if let Err(errors) = parse_str(text, "fuzz.toml") {
        assert_placed(text, &errors);
    }
}

/// One edit of a scenario's lines.
#[derive(Debug, Clone)]
enum Mutation {
    Delete(usize),
    Duplicate(usize),
    Swap(usize, usize),
    /// Replace the n-th digit of the text by another digit.
    Digit(usize, u8),
    /// Insert text at a byte position (moved back to a character boundary).
    Insert(usize, String),
    /// Replace the n-th `=` by something else.
    Equals(usize, String),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    let junk = prop_oneof![
        Just("-".to_owned()),
        Just("nan".to_owned()),
        Just("inf".to_owned()),
        Just("\"".to_owned()),
        Just("[".to_owned()),
        Just("]]".to_owned()),
        Just("{".to_owned()),
        Just("\n[[uav]]\n".to_owned()),
        Just("\n[[uav.sensor]]\nkind = \"lidar\"\n".to_owned()),
        Just("\n[[world.obstacle]]\nkind = \"pillars\"\n".to_owned()),
        Just("e400".to_owned()),
        Just("1979-05-27".to_owned()),
        Just(".".to_owned()),
        Just("_x".to_owned()),
        "[ -~]{0,12}",
        ".{0,4}",
    ];
    prop_oneof![
        any::<usize>().prop_map(Mutation::Delete),
        any::<usize>().prop_map(Mutation::Duplicate),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Mutation::Swap(a, b)),
        (any::<usize>(), 0u8..10).prop_map(|(n, d)| Mutation::Digit(n, d)),
        (any::<usize>(), junk.clone()).prop_map(|(at, text)| Mutation::Insert(at, text)),
        (any::<usize>(), junk).prop_map(|(n, text)| Mutation::Equals(n, text)),
    ]
}

fn apply(text: &str, mutation: &Mutation) -> String {
    let mut lines: Vec<&str> = text.lines().collect();
    let n = lines.len().max(1);
    match mutation {
        Mutation::Delete(i) => {
            if !lines.is_empty() {
                lines.remove(i % n);
            }
            lines.join("\n")
        }
        Mutation::Duplicate(i) => {
            if !lines.is_empty() {
                lines.insert(i % n, lines[i % n]);
            }
            lines.join("\n")
        }
        Mutation::Swap(a, b) => {
            if !lines.is_empty() {
                lines.swap(a % n, b % n);
            }
            lines.join("\n")
        }
        Mutation::Digit(k, digit) => {
            let digits: Vec<usize> = text
                .char_indices()
                .filter(|(_, c)| c.is_ascii_digit())
                .map(|(i, _)| i)
                .collect();
            let mut out = text.to_owned();
            if let Some(&at) = digits.get(k % digits.len().max(1)) {
                out.replace_range(at..at + 1, &digit.to_string());
            }
            out
        }
        Mutation::Insert(at, junk) => {
            let mut at = at % (text.len() + 1);
            while !text.is_char_boundary(at) {
                at -= 1;
            }
            let mut out = text.to_owned();
            out.insert_str(at, junk);
            out
        }
        Mutation::Equals(k, junk) => {
            let equals: Vec<usize> = text.match_indices('=').map(|(i, _)| i).collect();
            let mut out = text.to_owned();
            if let Some(&at) = equals.get(k % equals.len().max(1)) {
                out.replace_range(at..at + 1, junk);
            }
            out
        }
    }
}

/// Text made of scenario-like pieces, so that more of it gets past the TOML parser.
fn tomlish() -> impl Strategy<Value = String> {
    let piece = prop_oneof![
        Just("\n".to_owned()),
        Just(" = ".to_owned()),
        Just("[[uav]]\n".to_owned()),
        Just("[[uav.sensor]]\n".to_owned()),
        Just("[uav.behaviour]\n".to_owned()),
        Just("[[world.obstacle]]\n".to_owned()),
        Just("[world.bounds]\n".to_owned()),
        Just("[map]\n".to_owned()),
        Just("kind".to_owned()),
        Just("\"scripted\"".to_owned()),
        Just("\"box\"".to_owned()),
        Just("\"lidar\"".to_owned()),
        Just("\"depth_camera\"".to_owned()),
        Just("name".to_owned()),
        Just("waypoints".to_owned()),
        Just("start".to_owned()),
        Just("position".to_owned()),
        Just("min".to_owned()),
        Just("max".to_owned()),
        Just("[1.0, 2.0, 3.0]".to_owned()),
        Just("[[1, 2], [3]]".to_owned()),
        Just("{ position = [0, 0, 1] }".to_owned()),
        Just("-1".to_owned()),
        Just("nan".to_owned()),
        Just("0.0".to_owned()),
        Just("\"x\"".to_owned()),
        Just("true".to_owned()),
        "[a-z_]{1,8}",
        "-?[0-9]{1,4}(\\.[0-9]{1,3})?",
    ];
    proptest::collection::vec(piece, 0..60).prop_map(|pieces| pieces.concat())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..2000)) {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("random.toml");
        std::fs::write(&path, &bytes).unwrap();
        if let Err(errors) = load(&path) {
            let text = String::from_utf8_lossy(&bytes);
            assert_placed(&text, &errors);
        }
    }

    #[test]
    fn random_tomlish_text_never_panics(text in tomlish()) {
        check_text(&text);
    }

    #[test]
    fn mutated_shipped_scenarios_never_panic(
        which in 0..SHIPPED.len(),
        mutations in proptest::collection::vec(mutation(), 1..6),
    ) {
        let text = mutations.iter().fold(SHIPPED[which].to_owned(), |text, m| apply(&text, m));
        check_text(&text);
    }

    #[test]
    fn mutated_shipped_plans_are_read_or_refused(
        which in 0..SHIPPED_PLANS.len(),
        mutations in proptest::collection::vec(mutation(), 1..6),
    ) {
        let text = mutations
            .iter()
            .fold(SHIPPED_PLANS[which].to_owned(), |text, m| apply(&text, m));
        match Plan::parse(&text, Path::new("plans/fuzz.toml")) {
            Err(error) => {
                let message = error.to_string();
                prop_assert!(message.starts_with("plans/fuzz.toml: "), "{message}");
                prop_assert!(message.len() > "plans/fuzz.toml: ".len());
            }
            // Expanding a plan at the run limit takes seconds: mutated digits make a few.
            Ok(plan) if plan.run_count() <= 100_000 => {
                let runs = expand(&plan);
                prop_assert_eq!(runs.len(), plan.run_count());
                let ids: BTreeSet<&str> = runs.iter().map(|run| run.id.as_str()).collect();
                prop_assert_eq!(ids.len(), runs.len(), "two runs share an id");
            }
            Ok(_) => {}
        }
    }
}

#[test]
fn the_unmutated_shipped_scenarios_load() {
    for text in SHIPPED {
        parse_str(text, Path::new("scenarios/x.toml")).unwrap_or_else(|e| panic!("{e}"));
    }
}

#[test]
fn a_huge_bad_entry_stays_fast_and_bounded() {
    // 5000 waypoints of two numbers each, inside a `kind` table: each error is located by
    // trial decodings, which are bounded per problem and per entry.
    let points = vec!["[1.0, 2.0]"; 5000].join(", ");
    let text = format!(
        "name = \"big\"\ntime_limit_s = 1.0\n[world.bounds]\nmin = [0, 0, 0]\nmax = [9, 9, 9]\n\
         [[uav]]\nname = \"a\"\nstart = {{ position = [1, 1, 1] }}\n\
         behaviour = {{ kind = \"scripted\", speed = 1.0, waypoints = [{points}] }}\n"
    );
    let started = std::time::Instant::now();
    let errors = parse_str(&text, "big.toml").unwrap_err();
    let elapsed = started.elapsed();
    assert_eq!(errors.diagnostics.len(), 51, "{errors}");
    // The entry's note comes first (it is placed at the `[[uav]]` header), then the first 50
    // bad waypoints in order.
    let (note, points) = errors.diagnostics.split_first().unwrap();
    assert_eq!((note.path.as_str(), note.line), ("uav[0]", 6));
    assert!(
        note.message
            .starts_with("more problems in this entry are not shown"),
        "{note}"
    );
    for (i, d) in points.iter().enumerate() {
        assert_eq!(d.path, format!("uav[0].behaviour.waypoints[{i}]"));
    }
    assert!(elapsed.as_secs_f64() < 20.0, "took {elapsed:?}");
}
