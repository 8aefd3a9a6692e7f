//! Time as tests of quotas need it (shared by the test binaries through `#[path]`).

/// Waits, if need be, for a minute with time left: quotas count in windows of a minute, and
/// a test that crossed into the next would see its counts reset.
pub async fn early_in_a_minute() {
    let second = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .unwrap()
        .as_secs()
        % 60;
    if second > 45 {
        tokio::time::sleep(std::time::Duration::from_secs(61 - second)).await;
    }
}
