use std::path::Path;

/// A copy of the shipped library `saved_policies/<task>` under `library`, so that a test's
/// runs read a library outside the checkout.
pub fn copy_library(task: &str, library: &Path) {
    let from = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("saved_policies")
        .join(task);
    let to = library.join(task);
    std::fs::create_dir_all(&to).unwrap();
    for entry in std::fs::read_dir(&from).unwrap() {
        let path = entry.unwrap().path();
        if path.is_file() {
            std::fs::copy(&path, to.join(path.file_name().unwrap())).unwrap();
        }
    }
}
