//! ARCHITECTURE.md is the newcomer's map: two pages (at most 1,300 words besides its table),
//! and every file its "Where to find it" table names exists.

use std::path::Path;

fn architecture() -> (String, std::path::PathBuf) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("tests/ sits in the workspace")
        .to_path_buf();
    let text = std::fs::read_to_string(root.join("ARCHITECTURE.md")).expect("ARCHITECTURE.md");
    (text, root)
}

/// The rows of the table under "## Where to find it".
fn table_rows(text: &str) -> Vec<&str> {
    let section = text
        .split("## Where to find it")
        .nth(1)
        .expect("a \"Where to find it\" section");
    let section = section.split("\n## ").next().unwrap_or(section);
    section
        .lines()
        .filter(|l| l.starts_with('|') && !l.starts_with("|---") && !l.starts_with("| to find"))
        .collect()
}

#[test]
fn every_path_in_the_table_exists() {
    let (text, root) = architecture();
    let rows = table_rows(&text);
    assert!(rows.len() >= 20, "the table has {} rows", rows.len());
    let mut paths = 0;
    for row in rows {
        let open = row
            .trim_matches('|')
            .split('|')
            .nth(1)
            .expect("two columns");
        let named: Vec<&str> = open.split('`').skip(1).step_by(2).collect();
        assert!(!named.is_empty(), "a row that names no file: {row}");
        for path in named {
            assert!(
                root.join(path).exists(),
                "{path} (in the row {row:?}) does not exist"
            );
            paths += 1;
        }
    }
    println!("{paths} paths checked");
}

#[test]
fn it_stays_two_pages() {
    let (text, _) = architecture();
    let table: usize = table_rows(&text)
        .iter()
        .map(|r| r.split_whitespace().count())
        .sum();
    let words = text.split_whitespace().count() - table;
    println!("{words} words besides the table");
    assert!(words <= 1300, "{words} words besides the table");
}
