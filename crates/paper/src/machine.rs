//! What Table 1 was measured on, and when: the CPU model (from
//! `/proc/cpuinfo` on Linux), the logical CPUs, the worker threads used,
//! the build, and the date (UTC, from the system clock, without a date
//! library).

use std::time::{SystemTime, UNIX_EPOCH};

/// The machine a table was measured on.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Machine {
    /// The CPU's model name, or `"unknown CPU"`.
    pub cpu: String,
    /// Logical CPUs the operating system offers this process.
    pub logical_cpus: usize,
    /// Worker threads the renders ran on.
    pub threads: usize,
}

impl Machine {
    /// This machine, rendering on `threads` worker threads.
    pub fn this(threads: usize) -> Self {
        let cpuinfo = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
        Machine {
            cpu: cpu_model(&cpuinfo).unwrap_or_else(|| "unknown CPU".to_string()),
            logical_cpus: std::thread::available_parallelism().map_or(1, |n| n.get()),
            threads,
        }
    }
}

/// The first `model name` in the text of `/proc/cpuinfo` (x86), else its
/// `Model` or `CPU part` line (ARM), with runs of blanks collapsed.
pub fn cpu_model(cpuinfo: &str) -> Option<String> {
    ["model name", "Model", "CPU part"].iter().find_map(|key| {
        cpuinfo.lines().find_map(|line| {
            let (k, v) = line.split_once(':')?;
            let v = v.split_whitespace().collect::<Vec<_>>().join(" ");
            (k.trim() == *key && !v.is_empty()).then_some(v)
        })
    })
}

/// How this crate was compiled: Table 1's times depend on it.
pub fn build_profile() -> &'static str {
    if cfg!(debug_assertions) {
        "a development build (optimised, with debug assertions): not comparable with release timings"
    } else {
        "a release build"
    }
}

/// Today's date in UTC, `YYYY-MM-DD`.
pub fn today_utc() -> String {
    let seconds = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    let (y, m, d) = civil_from_days((seconds / 86_400) as i64);
    format!("{y:04}-{m:02}-{d:02}")
}

/// The proleptic Gregorian date `days` days after 1970-01-01 (H. Hinnant,
/// "chrono-Compatible Low-Level Date Algorithms", `civil_from_days`).
pub fn civil_from_days(days: i64) -> (i64, u32, u32) {
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097); // day of the 400-year era, 0..=146096
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365; // 0..=399
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100); // day of the year from 1 March
    let mp = (5 * doy + 2) / 153; // month from March, 0..=11
    let day = (doy - (153 * mp + 2) / 5 + 1) as u32;
    let month = if mp < 10 { mp + 3 } else { mp - 9 } as u32;
    let year = yoe + era * 400 + i64::from(month <= 2);
    (year, month, day)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_from_day_numbers() {
        assert_eq!(civil_from_days(0), (1970, 1, 1));
        assert_eq!(civil_from_days(-1), (1969, 12, 31));
        assert_eq!(civil_from_days(59), (1970, 3, 1));
        // 2000 was a leap year: 29 February is day 11 016.
        assert_eq!(civil_from_days(11_016), (2000, 2, 29));
        assert_eq!(civil_from_days(11_017), (2000, 3, 1));
        // 1900 was not (day −25 508 is 1900-03-01).
        assert_eq!(civil_from_days(-25_509), (1900, 2, 28));
        assert_eq!(civil_from_days(-25_508), (1900, 3, 1));
        // The paper was received on 14 August 1992.
        assert_eq!(civil_from_days(8_261), (1992, 8, 14));
        assert_eq!(civil_from_days(20_000), (2024, 10, 4));
        let today = today_utc();
        assert_eq!(today.len(), 10);
        assert!(today.as_str() > "2024-01-01", "{today}");
    }

    #[test]
    fn cpu_model_from_cpuinfo() {
        let x86 = "processor\t: 0\nvendor_id\t: AuthenticAMD\nmodel\t\t: 1\n\
                   model name\t: AMD EPYC   7B13 64-Core Processor\nprocessor\t: 1\n\
                   model name\t: AMD EPYC 7B13 64-Core Processor\n";
        assert_eq!(
            cpu_model(x86).as_deref(),
            Some("AMD EPYC 7B13 64-Core Processor")
        );
        let arm =
            "processor\t: 0\nBogoMIPS\t: 48.00\nCPU part\t: 0xd0c\n\nModel\t: Raspberry Pi 4\n";
        assert_eq!(cpu_model(arm).as_deref(), Some("Raspberry Pi 4"));
        assert_eq!(cpu_model("processor : 0\nmodel name :   \n"), None);
        assert_eq!(cpu_model(""), None);
    }
}
