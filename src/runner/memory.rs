//! The memory the runs of a matrix may use together: the machine's available memory when the
//! matrix starts, or what `--memory` says. A run whose estimate (`solver::Job::estimated_bytes`)
//! exceeds it is refused and recorded as failed; the others start only while the estimates of
//! the runs in progress leave room for theirs, so which runs are refused and which numbers
//! they give do not depend on `--jobs`.

use std::fs;
use std::sync::{Condvar, Mutex};

/// How a refused run's message begins; a rerun computes such runs again, under the limit it
/// then has.
pub const REFUSED: &str = "not run: ";

pub struct MemoryBudget {
    /// Bytes, or none when the machine does not say (no /proc/meminfo) and none was given.
    limit: Option<f64>,
    /// Where the limit comes from, for the messages.
    source: String,
    in_use: Mutex<f64>,
    released: Condvar,
}

impl MemoryBudget {
    /// `given` bytes, else MemAvailable of /proc/meminfo.
    pub fn new(given: Option<u64>) -> Self {
        let (limit, source) = match given {
            Some(bytes) => (Some(bytes as f64), "--memory".to_string()),
            None => match available_bytes() {
                Some(bytes) => (Some(bytes), "the memory available when the matrix started (MemAvailable; --memory sets another)".to_string()),
                None => (None, String::new()),
            },
        };
        MemoryBudget {
            limit,
            source,
            in_use: Mutex::new(0.0),
            released: Condvar::new(),
        }
    }

    /// Why a run estimated at `bytes` cannot run at all, if it cannot.
    pub fn refusal(&self, bytes: f64) -> Option<String> {
        let limit = self.limit?;
        (bytes > limit).then(|| {
            format!(
                "{REFUSED}it needs an estimated {} of memory, more than the {} of {}",
                human(bytes),
                human(limit),
                self.source
            )
        })
    }

    /// Waits until `bytes` fit beside the runs in progress (at once when none is), and holds
    /// them until the returned hold is dropped.
    pub fn hold(&self, bytes: f64) -> Hold<'_> {
        let mut in_use = lock(&self.in_use);
        if let Some(limit) = self.limit {
            while *in_use > 0.0 && *in_use + bytes > limit {
                in_use = self
                    .released
                    .wait(in_use)
                    .unwrap_or_else(|poisoned| poisoned.into_inner());
            }
        }
        *in_use += bytes;
        Hold {
            budget: self,
            bytes,
        }
    }
}

/// Memory held by a run in progress.
pub struct Hold<'a> {
    budget: &'a MemoryBudget,
    bytes: f64,
}

impl Drop for Hold<'_> {
    fn drop(&mut self) {
        *lock(&self.budget.in_use) -= self.bytes;
        self.budget.released.notify_all();
    }
}

/// A poisoned lock holds a value as good as any: every update is a single step.
fn lock(m: &Mutex<f64>) -> std::sync::MutexGuard<'_, f64> {
    m.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

fn available_bytes() -> Option<f64> {
    let text = fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

/// Bytes in the largest binary unit that keeps the number at least 1.
pub fn human(bytes: f64) -> String {
    let units = ["B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    let mut value = bytes;
    let mut unit = 0;
    while value >= 1024.0 && unit + 1 < units.len() {
        value /= 1024.0;
        unit += 1;
    }
    format!("{value:.1} {}", units[unit])
}

/// A size as `--memory` takes it: bytes, or a number with K, M, G or T (powers of 1024,
/// optionally followed by "iB" or "B").
pub fn parse_size(text: &str) -> Result<u64, String> {
    let t = text.trim();
    let digits = t
        .find(|c: char| !(c.is_ascii_digit() || c == '.'))
        .unwrap_or(t.len());
    let (number, unit) = t.split_at(digits);
    let value: f64 = number
        .parse()
        .map_err(|_| format!("'{text}' is not a size such as 8G, 512M or 2000000000"))?;
    let power = match unit.trim().to_ascii_uppercase().as_str() {
        "" | "B" => 0,
        "K" | "KB" | "KIB" => 1,
        "M" | "MB" | "MIB" => 2,
        "G" | "GB" | "GIB" => 3,
        "T" | "TB" | "TIB" => 4,
        other => {
            return Err(format!(
                "'{text}': unknown unit '{other}'; valid: K, M, G, T (powers of 1024)"
            ))
        }
    };
    Ok((value * 1024f64.powi(power)) as u64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_in_powers_of_1024() {
        assert_eq!(parse_size("2000").unwrap(), 2000);
        assert_eq!(parse_size("512M").unwrap(), 512 << 20);
        assert_eq!(parse_size("1.5GiB").unwrap(), 3 << 29);
        assert!(parse_size("8X").unwrap_err().contains("valid: K, M, G, T"));
        assert!(parse_size("lots").is_err());
        assert_eq!(human(1.5 * (1u64 << 30) as f64), "1.5 GiB");
    }

    #[test]
    fn a_run_larger_than_the_limit_is_refused_and_holds_wait_for_room() {
        let budget = MemoryBudget::new(Some(100));
        let message = budget.refusal(150.0).unwrap();
        assert!(message.starts_with(REFUSED), "{message}");
        assert!(message.contains("150.0 B") && message.contains("100.0 B of --memory"));
        assert!(budget.refusal(100.0).is_none());
        let first = budget.hold(60.0);
        std::thread::scope(|scope| {
            let waiting = scope.spawn(|| {
                let _second = budget.hold(60.0);
                let in_use = *lock(&budget.in_use);
                in_use
            });
            std::thread::sleep(std::time::Duration::from_millis(50));
            assert_eq!(*lock(&budget.in_use), 60.0, "the second hold waits");
            drop(first);
            assert_eq!(waiting.join().unwrap(), 60.0);
        });
        assert_eq!(*lock(&budget.in_use), 0.0);
    }
}
