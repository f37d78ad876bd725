//! A sweep on a Slurm cluster (`nbv sweep submit`): a job array of the grid's shards, each
//! task an `nbv sweep run … --shard I/N` into `OUT/shards/shard_I`, and a merge job that runs
//! once every task succeeded (`--dependency=afterok`) and unions the shards into `OUT` with
//! the gates. The sweep's resume makes a resubmission whole: each task skips the episodes its
//! shard already finished, so after cancelled, failed or killed tasks the same command runs
//! only what is missing and merges again. The previous submission's jobs, if still queued
//! or running, are cancelled first (a merge left pending by a failed task is never left
//! waiting; `--kill-on-invalid-dep=yes` also ends it).
//!
//! ```text
//! OUT/slurm/array.sbatch      the array: one task per shard
//! OUT/slurm/merge.sbatch      the merge and the gates
//! OUT/slurm/jobs.json         the job ids of the last submission
//! OUT/slurm/task-<job>_<i>.out, merge-<job>.out   the jobs' output
//! OUT/shards/shard_<i>/       each shard's sweep directory
//! OUT/results.csv, summary.json, …                the merged sweep
//! ```

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Duration;

use crate::error::{Context, Result, bail};

/// What to submit.
#[derive(Debug, Clone, PartialEq)]
pub struct Submission {
    /// The `nbv` binary the jobs run (absolute: on a multi-node cluster, a path every node
    /// sees).
    pub nbv: PathBuf,
    /// The grid file (absolute).
    pub grid: PathBuf,
    /// The output directory (absolute; on a shared filesystem for several nodes).
    pub out: PathBuf,
    /// Array tasks: shard `I` of `shards` each.
    pub shards: usize,
    /// Episodes each task runs at once (its `--cpus-per-task`).
    pub jobs: usize,
    /// The merge's `--require` gates, as given.
    pub require: Vec<String>,
    /// Extra `#SBATCH` options for both jobs (`--time=2:00:00`, `--partition=…`).
    pub sbatch_args: Vec<String>,
}

/// The job ids of a submission.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Submitted {
    /// The array job.
    pub array: String,
    /// The merge job.
    pub merge: String,
}

/// How a job ended.
#[derive(Debug, Clone, PartialEq)]
pub struct JobEnd {
    /// Slurm's state (`COMPLETED`, `FAILED`, `CANCELLED`, `TIMEOUT`, …).
    pub state: String,
    /// The job script's exit code.
    pub exit_code: i32,
}

/// Quotes a word for a POSIX shell.
fn quote(word: &str) -> String {
    if !word.is_empty()
        && word
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "/._-=:,+@%".contains(c))
    {
        word.to_string()
    } else {
        format!("'{}'", word.replace('\'', r"'\''"))
    }
}

impl Submission {
    /// `OUT/slurm`.
    pub fn slurm_dir(&self) -> PathBuf {
        self.out.join("slurm")
    }

    fn header(&self, lines: &[String]) -> String {
        let mut s = String::from("#!/bin/bash\n");
        for l in lines {
            s += &format!("#SBATCH {l}\n");
        }
        for a in &self.sbatch_args {
            s += &format!("#SBATCH {a}\n");
        }
        s
    }

    /// The array job's script.
    ///
    /// ```
    /// use nbv_sweep::slurm::Submission;
    /// let s = Submission {
    ///     nbv: "/opt/nbv".into(), grid: "/g.toml".into(), out: "/o".into(), shards: 3, jobs: 2,
    ///     require: vec![], sbatch_args: vec!["--time=1:00:00".into()],
    /// };
    /// let script = s.array_script();
    /// assert!(script.contains("#SBATCH --array=0-2\n"));
    /// assert!(script.contains("#SBATCH --cpus-per-task=2\n"));
    /// assert!(script.contains("#SBATCH --time=1:00:00\n"));
    /// assert!(script.contains("--shard \"$SLURM_ARRAY_TASK_ID/3\""));
    /// ```
    pub fn array_script(&self) -> String {
        let slurm = self.slurm_dir();
        let mut s = self.header(&[
            "--job-name=nbv-sweep".into(),
            format!("--array=0-{}", self.shards.max(1) - 1),
            format!("--cpus-per-task={}", self.jobs.max(1)),
            format!(
                "--output={}",
                quote(&slurm.join("task-%A_%a.out").display().to_string())
            ),
        ]);
        s += &format!(
            "# Task I runs the episodes of {grid} whose index mod {n} is I, into its shard\n\
             # directory; finished episodes there are skipped, so a resubmission runs only what\n\
             # is missing.\n\
             set -euo pipefail\n\
             exec {nbv} sweep run {grid} -o {out}/shards/shard_\"$SLURM_ARRAY_TASK_ID\" \\\n    \
             --shard \"$SLURM_ARRAY_TASK_ID/{n}\" --jobs {jobs} -q\n",
            nbv = quote(&self.nbv.display().to_string()),
            grid = quote(&self.grid.display().to_string()),
            out = quote(&self.out.display().to_string()),
            n = self.shards.max(1),
            jobs = self.jobs.max(1),
        );
        s
    }

    /// The merge job's script: the shards into `OUT`, then the gates (exit 4 when one
    /// fails).
    pub fn merge_script(&self) -> String {
        let slurm = self.slurm_dir();
        let mut s = self.header(&[
            "--job-name=nbv-merge".into(),
            "--cpus-per-task=1".into(),
            format!(
                "--output={}",
                quote(&slurm.join("merge-%j.out").display().to_string())
            ),
        ]);
        let shards: Vec<String> = (0..self.shards.max(1))
            .map(|i| {
                quote(
                    &self
                        .out
                        .join(format!("shards/shard_{i}"))
                        .display()
                        .to_string(),
                )
            })
            .collect();
        let gates: String = self
            .require
            .iter()
            .map(|g| format!(" \\\n    --require {}", quote(g)))
            .collect();
        s += &format!(
            "# Runs once every task of the array succeeded: the shards' rows into {out},\n\
             # results.csv and summary.json there, and the gates (exit status 4 if one fails).\n\
             set -euo pipefail\n\
             exec {nbv} sweep merge {shards} \\\n    -o {out}{gates}\n",
            nbv = quote(&self.nbv.display().to_string()),
            shards = shards.join(" "),
            out = quote(&self.out.display().to_string()),
        );
        s
    }

    /// Writes both scripts into `OUT/slurm/` and returns their paths.
    pub fn write_scripts(&self) -> Result<(PathBuf, PathBuf)> {
        let dir = self.slurm_dir();
        std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
        let array = dir.join("array.sbatch");
        let merge = dir.join("merge.sbatch");
        for (path, text) in [(&array, self.array_script()), (&merge, self.merge_script())] {
            nbv_core::atomic_file::write_atomic(path, text.as_bytes())
                .with_context(|| format!("writing {}", path.display()))?;
        }
        Ok((array, merge))
    }

    /// Writes the scripts, cancels the previous submission's jobs still queued or
    /// running, submits the array and the merge after it, and records their ids in
    /// `OUT/slurm/jobs.json`.
    pub fn submit(&self) -> Result<Submitted> {
        let (array, merge) = self.write_scripts()?;
        let jobs = self.slurm_dir().join("jobs.json");
        if let Ok(text) = std::fs::read_to_string(&jobs)
            && let Ok(previous) = serde_json::from_str::<Submitted>(&text)
        {
            // Finished jobs are no longer known to scancel: its complaint is no error.
            let _ = Command::new("scancel")
                .args([&previous.merge, &previous.array])
                .output();
        }
        let array_id = sbatch(&[], &array)?;
        let merge_id = sbatch(
            &[
                format!("--dependency=afterok:{array_id}"),
                "--kill-on-invalid-dep=yes".into(),
            ],
            &merge,
        )?;
        let submitted = Submitted {
            array: array_id,
            merge: merge_id,
        };
        crate::layout::write_json(&jobs, &submitted)?;
        Ok(submitted)
    }
}

/// `sbatch --parsable ARGS SCRIPT`: the job id.
fn sbatch(args: &[String], script: &Path) -> Result<String> {
    let out = Command::new("sbatch")
        .arg("--parsable")
        .args(args)
        .arg(script)
        .output()
        .context("running sbatch (is Slurm installed and on PATH?)")?;
    if !out.status.success() {
        bail!(
            "sbatch {}: {}",
            script.display(),
            String::from_utf8_lossy(&out.stderr).trim()
        );
    }
    let text = String::from_utf8_lossy(&out.stdout);
    // `--parsable` prints `id` or `id;cluster`.
    let id = text.trim().split(';').next().unwrap_or("").to_string();
    if id.is_empty() || !id.chars().all(|c| c.is_ascii_digit()) {
        bail!(
            "sbatch {}: no job id in {:?}",
            script.display(),
            text.trim()
        );
    }
    Ok(id)
}

/// The state of a job (`None` once Slurm forgot it), from `scontrol show job`.
pub fn job_state(id: &str) -> Result<Option<JobEnd>> {
    let out = Command::new("scontrol")
        .args(["show", "job", id, "--oneliner"])
        .output()
        .context("running scontrol")?;
    if !out.status.success() {
        return Ok(None);
    }
    Ok(parse_job(&String::from_utf8_lossy(&out.stdout)))
}

/// The state and exit code in `scontrol show job --oneliner`'s text (the first job).
fn parse_job(text: &str) -> Option<JobEnd> {
    let field = |key: &str| {
        text.split_whitespace()
            .find_map(|w| w.strip_prefix(key))
            .map(str::to_string)
    };
    let state = field("JobState=")?;
    let exit_code = field("ExitCode=")
        .and_then(|e| e.split(':').next().and_then(|c| c.parse().ok()))
        .unwrap_or(0);
    Some(JobEnd { state, exit_code })
}

/// Waits until job `id` has ended (polling every `every`), and says how.
pub fn wait_for(id: &str, every: Duration) -> Result<JobEnd> {
    loop {
        match job_state(id)? {
            Some(end) if is_final(&end.state) => return Ok(end),
            Some(_) => {}
            None => bail!("job {id}: Slurm no longer knows it"),
        }
        std::thread::sleep(every);
    }
}

/// Whether a job in `state` has ended.
fn is_final(state: &str) -> bool {
    !matches!(
        state,
        "PENDING"
            | "RUNNING"
            | "CONFIGURING"
            | "COMPLETING"
            | "SUSPENDED"
            | "REQUEUED"
            | "RESIZING"
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_scontrol() {
        let t = "JobId=12 JobName=nbv-merge UserId=root(0) JobState=FAILED Reason=NonZeroExitCode Dependency=(null) ExitCode=4:0 RunTime=00:00:01";
        assert_eq!(
            parse_job(t),
            Some(JobEnd {
                state: "FAILED".into(),
                exit_code: 4
            })
        );
        assert!(!is_final("PENDING") && is_final("CANCELLED") && is_final("COMPLETED"));
    }

    #[test]
    fn quotes_what_the_shell_would_split() {
        assert_eq!(quote("/a/b.toml"), "/a/b.toml");
        assert_eq!(quote("f_score>=0.8"), "'f_score>=0.8'");
        assert_eq!(quote("it's"), r"'it'\''s'");
    }

    /// The merge names every shard and every gate.
    #[test]
    fn merge_script_names_every_shard_and_gate() {
        let s = Submission {
            nbv: "/bin/nbv".into(),
            grid: "/g.toml".into(),
            out: "/out dir".into(),
            shards: 2,
            jobs: 1,
            require: vec!["collisions==0".into()],
            sbatch_args: vec![],
        };
        let m = s.merge_script();
        assert!(
            m.contains("'/out dir/shards/shard_0' '/out dir/shards/shard_1'"),
            "{m}"
        );
        assert!(m.contains("--require collisions==0"), "{m}");
        assert!(m.contains("-o '/out dir'"), "{m}");
    }
}
