use super::*;

/// A crate in a scratch directory: `(file, text)` under `src/`.
fn fixture(files: &[(&str, &str)]) -> (tempfile::TempDir, CrateModules) {
    let dir = tempfile::tempdir().unwrap();
    for (name, text) in files {
        let path = dir.path().join("src").join(name);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, text).unwrap();
    }
    let modules = CrateModules::load(&dir.path().join("src/lib.rs")).unwrap();
    (dir, modules)
}

fn names(c: &CrateModules) -> Vec<Vec<String>> {
    circles(c)
        .iter()
        .map(|files| {
            let name = |f: &PathBuf| f.file_name().unwrap().to_string_lossy().into_owned();
            files.iter().map(name).collect()
        })
        .collect()
}

#[test]
fn a_circle_through_a_re_export_and_a_macro_argument_is_found() {
    let (_dir, c) = fixture(&[
        ("lib.rs", "mod a;\nmod b;\npub use a::Alpha;\n"),
        (
            "a.rs",
            "pub struct Alpha;\npub fn show() { println!(\"{}\", crate::b::beta()); }\n",
        ),
        ("b.rs", "pub fn beta() -> u8 { let _ = crate::Alpha; 1 }\n"),
    ]);
    assert_eq!(names(&c), vec![vec!["a.rs", "b.rs"]]);
}

#[test]
fn visibility_tests_and_facades_are_not_imports() {
    let (_dir, c) = fixture(&[
        ("lib.rs", "mod a;\nmod b;\npub use b::beta;\n"),
        (
            "a.rs",
            "pub(crate) fn alpha() -> u8 { crate::b::beta() }\n\
             #[cfg(test)]\nmod tests { fn t() { let _ = crate::b::beta(); } }\n",
        ),
        (
            "b.rs",
            "pub(in crate) fn beta() -> u8 { 1 }\n\
             #[cfg(test)]\nmod tests { fn t() { let _ = crate::a::alpha(); } }\n",
        ),
    ]);
    assert!(names(&c).is_empty(), "{:?}", names(&c));
    assert_eq!(c.production_files().count(), 3);
}

#[test]
fn a_path_through_an_imported_module_name_is_an_import() {
    let (_dir, c) = fixture(&[
        ("lib.rs", "mod a;\nmod b;\n"),
        (
            "a.rs",
            "use crate::b;\npub struct Alpha;\npub fn f() -> u8 { b::inner::beta() }\n",
        ),
        (
            "b.rs",
            "pub mod inner { pub fn beta() -> u8 { let _ = crate::a::Alpha; 1 } }\n",
        ),
    ]);
    assert_eq!(names(&c), vec![vec!["a.rs", "b.rs"]]);
}
