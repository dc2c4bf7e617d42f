//! Which share of the plan a process makes: `--shard K/N`, or inside a Slurm job array
//! the task's `SLURM_ARRAY_TASK_ID` (less `SLURM_ARRAY_TASK_MIN`) of
//! `SLURM_ARRAY_TASK_COUNT` (Slurm `sbatch(1)`, "OUTPUT ENVIRONMENT VARIABLES").

use std::ops::Range;

use crate::error::{Error, Result};

/// Share `k` of `n` (0-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// This share.
    pub k: usize,
    /// Shares in all.
    pub n: usize,
}

impl Shard {
    /// The whole plan.
    pub const ALL: Shard = Shard { k: 0, n: 1 };

    /// `k` of `n`, checked.
    ///
    /// # Errors
    ///
    /// [`Error::Argument`] naming `what` when `n` is 0 or `k ≥ n`.
    pub fn new(k: usize, n: usize, what: &str) -> Result<Shard> {
        if n == 0 {
            return Err(Error::Argument { what: what.into(), message: "N must be at least 1".into() });
        }
        if k >= n {
            return Err(Error::Argument {
                what: what.into(),
                message: format!("K = {k} must be below N = {n} (K counts from 0)"),
            });
        }
        Ok(Shard { k, n })
    }

    /// Parses `K/N`.
    ///
    /// # Errors
    ///
    /// [`Error::Argument`] for another form, `N = 0` or `K ≥ N`.
    pub fn parse(text: &str) -> Result<Shard> {
        let bad =
            || Error::Argument { what: "--shard".into(), message: format!("expected K/N (e.g. 0/4), found {text:?}") };
        let (k, n) = text.split_once('/').ok_or_else(bad)?;
        let k = k.trim().parse().map_err(|_| bad())?;
        let n = n.trim().parse().map_err(|_| bad())?;
        Shard::new(k, n, "--shard")
    }

    /// The share of the Slurm array task running this process, from `env` (a lookup
    /// such as `std::env::var`); `None` outside an array.
    ///
    /// # Errors
    ///
    /// [`Error::Argument`] for malformed or inconsistent variables.
    pub fn from_slurm(env: impl Fn(&str) -> Option<String>) -> Result<Option<Shard>> {
        let Some(id) = env("SLURM_ARRAY_TASK_ID") else { return Ok(None) };
        let num = |name: &str, v: &str| {
            v.trim().parse::<usize>().map_err(|_| Error::Argument {
                what: name.into(),
                message: format!("expected an integer, found {v:?}"),
            })
        };
        let id = num("SLURM_ARRAY_TASK_ID", &id)?;
        let count = env("SLURM_ARRAY_TASK_COUNT").ok_or_else(|| Error::Argument {
            what: "SLURM_ARRAY_TASK_COUNT".into(),
            message: "missing while SLURM_ARRAY_TASK_ID is set".into(),
        })?;
        let count = num("SLURM_ARRAY_TASK_COUNT", &count)?;
        let min = match env("SLURM_ARRAY_TASK_MIN") {
            Some(m) => num("SLURM_ARRAY_TASK_MIN", &m)?,
            None => 0,
        };
        let k = id.checked_sub(min).ok_or_else(|| Error::Argument {
            what: "SLURM_ARRAY_TASK_ID".into(),
            message: format!("{id} is below SLURM_ARRAY_TASK_MIN {min}"),
        })?;
        Shard::new(k, count, "SLURM_ARRAY_TASK_ID").map(Some)
    }

    /// The variants of this share among `len`: a contiguous block, the blocks as even
    /// as they can be (`⌊k·len/n⌋ .. ⌊(k+1)·len/n⌋`).
    pub fn range(&self, len: usize) -> Range<usize> {
        (self.k * len / self.n)..((self.k + 1) * len / self.n)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shares_cover_the_plan_once() {
        for n in 1..20 {
            let mut seen = vec![0; 130];
            for k in 0..n {
                for i in Shard::new(k, n, "t").unwrap().range(130) {
                    seen[i] += 1;
                }
            }
            assert!(seen.iter().all(|&c| c == 1));
        }
        assert_eq!(Shard::parse("3/13").unwrap().range(130), 30..40);
        assert!(Shard::parse("13/13").unwrap_err().to_string().contains("K = 13 must be below N = 13"));
        assert!(Shard::parse("1/0").is_err());
        assert!(Shard::parse("1-4").is_err());
    }

    #[test]
    fn slurm_variables() {
        let env = |vars: &'static [(&'static str, &'static str)]| {
            move |k: &str| vars.iter().find(|(n, _)| *n == k).map(|(_, v)| v.to_string())
        };
        assert_eq!(Shard::from_slurm(env(&[])).unwrap(), None);
        let s = Shard::from_slurm(env(&[("SLURM_ARRAY_TASK_ID", "5"), ("SLURM_ARRAY_TASK_COUNT", "13")])).unwrap();
        assert_eq!(s, Some(Shard { k: 5, n: 13 }));
        let s = Shard::from_slurm(env(&[
            ("SLURM_ARRAY_TASK_ID", "6"),
            ("SLURM_ARRAY_TASK_MIN", "1"),
            ("SLURM_ARRAY_TASK_COUNT", "13"),
        ]))
        .unwrap();
        assert_eq!(s, Some(Shard { k: 5, n: 13 }));
        assert!(Shard::from_slurm(env(&[("SLURM_ARRAY_TASK_ID", "13"), ("SLURM_ARRAY_TASK_COUNT", "13")])).is_err());
        assert!(Shard::from_slurm(env(&[("SLURM_ARRAY_TASK_ID", "1")])).is_err());
    }
}
