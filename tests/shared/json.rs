//! Reading answers' JSON as tests need it (shared by the test binaries through `#[path]`).

use serde_json::Value;

/// The string `field` of each item of the array `items`, in its order.
pub fn field_of_each<'a>(items: &'a Value, field: &str) -> Vec<&'a str> {
    items
        .as_array()
        .unwrap()
        .iter()
        .map(|item| item[field].as_str().unwrap())
        .collect()
}
