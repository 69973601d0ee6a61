//! `mirrorbox merge OUT DIR...` (issue 20): the shards of one sweep (`sweep --shard I/N`, each
//! in its own folder) joined into one sweep folder — one `results.jsonl`, the pictures its
//! records name, a `sweep.json` listing where each shard ran — and its reports regenerated.
//!
//! Refused, naming the folder: a folder that is not a shard, shards of different sweeps
//! (their lists of every point's key differ), two shards with one index or count, a point
//! measured twice, a point no shard measured, a record naming a picture that is not a file in
//! its shard's `images/`. Nothing is written before every check passed, and a folder a merge
//! made is removed again if writing it fails.

use crate::HarnessError;
use mirrorbox_files::{FolderLock, write_atomically};
use mirrorbox_report::{Record, ShardInfo, SweepInfo, read_records, write_report};
use mirrorbox_scene::limits::SettingError;
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// Most shard folders one merge reads.
pub const MAX_MERGED_SHARDS: usize = 100_000;

fn refused(folder: &Path, what: impl Into<String>) -> HarnessError {
    HarnessError::Setting(SettingError::new(
        "merge DIR",
        what.into(),
        folder.display().to_string(),
    ))
}

struct ShardFolder {
    dir: PathBuf,
    info: SweepInfo,
    records: Vec<Record>,
}

fn read_shard(dir: &Path) -> Result<ShardFolder, HarnessError> {
    let info_path = dir.join("sweep.json");
    let text = mirrorbox_files::read_bounded_text(
        &info_path,
        mirrorbox_report::MAX_SWEEP_JSON_BYTES,
        "a sweep description",
    )
    .map_err(|e| refused(dir, format!("a shard's folder (sweep.json: {e})")))?;
    let info: SweepInfo = serde_json::from_str(&text).map_err(|e| {
        refused(
            dir,
            format!("a shard's folder (sweep.json is not one: {e})"),
        )
    })?;
    if info.shard.is_none() || info.point_keys.is_empty() {
        return Err(refused(
            dir,
            "a shard's folder (written by `sweep --shard I/N`; this sweep was not sharded)",
        ));
    }
    let results = dir.join("results.jsonl");
    let records = read_records(&results)?;
    Ok(ShardFolder {
        dir: dir.to_path_buf(),
        info,
        records,
    })
}

/// What a merge did.
pub struct Merged {
    pub shards: usize,
    pub points: usize,
    /// The distinct devices the shards ran on (timings compare only within one).
    pub devices: Vec<String>,
}

/// Merges the shard folders `dirs` into the sweep folder `out` (created inside an existing
/// folder) and writes its reports; `command` is recorded as the merged sweep's command.
/// `sections`: the experiments' report sections (the registry's) for the merged report.
pub fn merge(
    out: &Path,
    dirs: &[PathBuf],
    command: &str,
    sections: &[mirrorbox_report::Section],
) -> Result<Merged, HarnessError> {
    if dirs.is_empty() || dirs.len() > MAX_MERGED_SHARDS {
        return Err(SettingError::new(
            "merge DIR...",
            format!("1 to {MAX_MERGED_SHARDS} shard folders"),
            dirs.len(),
        )
        .into());
    }
    let shards = dirs
        .iter()
        .map(|d| read_shard(d))
        .collect::<Result<Vec<_>, _>>()?;
    let first = &shards[0];
    let mut indices: HashMap<String, &Path> = HashMap::new();
    for s in &shards {
        if s.info.point_keys != first.info.point_keys {
            return Err(refused(
                &s.dir,
                format!(
                    "a shard of the same sweep as {} (its configuration — methods, axes, scene, \
                     size, frames — gives other points)",
                    first.dir.display()
                ),
            ));
        }
        let shard = s.info.shard.clone().unwrap_or_default();
        let count = |t: &str| t.split('/').nth(1).map(str::to_string);
        if count(&shard) != count(first.info.shard.as_deref().unwrap_or_default()) {
            return Err(refused(
                &s.dir,
                format!(
                    "shards split one way (it is shard {shard}, {} is shard {})",
                    first.dir.display(),
                    first.info.shard.as_deref().unwrap_or_default()
                ),
            ));
        }
        if let Some(other) = indices.insert(shard.clone(), &s.dir) {
            return Err(refused(
                &s.dir,
                format!(
                    "one folder per shard (shard {shard} is also {})",
                    other.display()
                ),
            ));
        }
    }
    // Every point exactly once, and no other (a record outside the sweep's points had been
    // dropped unsaid, its pictures copied all the same).
    let mut seen: HashMap<&str, &Path> = HashMap::new();
    for s in &shards {
        for r in &s.records {
            if !first.info.point_keys.contains(&r.key) {
                return Err(refused(
                    &s.dir,
                    format!(
                        "a shard of the sweep's points only ({:?} is none of them)",
                        r.key
                    ),
                ));
            }
            if let Some(other) = seen.insert(r.key.as_str(), &s.dir) {
                return Err(refused(
                    &s.dir,
                    format!(
                        "each point in one shard (point {:?} is also in {})",
                        r.key,
                        other.display()
                    ),
                ));
            }
        }
    }
    let missing: Vec<&String> = first
        .info
        .point_keys
        .iter()
        .filter(|k| !seen.contains_key(k.as_str()))
        .collect();
    if let Some(k) = missing.first() {
        return Err(SettingError::new(
            "merge DIR...",
            "the folders of every shard, each finished",
            format!(
                "{} of {} points measured by none of them (first: {k:?})",
                missing.len(),
                first.info.point_keys.len()
            ),
        )
        .into());
    }
    // Every picture a record names is a file in its shard's images/, before anything is
    // written.
    for s in &shards {
        for r in &s.records {
            crate::check_record_pictures(&s.dir, r).map_err(|e| {
                refused(
                    &s.dir,
                    format!("a shard whose pictures are files in its images/ folder ({e})"),
                )
            })?;
        }
    }
    // Write: the folder, its pictures, the records in the sweep's order, the description —
    // into OUT.partial, which then takes OUT's place: a merge that fails leaves no folder
    // half-written, and an earlier merge in OUT whole (it had had new pictures under its old
    // records).
    crate::check_output_parent(out)?;
    check_merge_out(out, &shards)?;
    for s in &shards {
        crate::exchange::not_the_stage_of(out, &s.dir)?;
    }
    // OUT's lock, held through the staging and the swap: a merge does not replace a folder
    // another process is writing (a sweep resumed into it, another merge).
    let _out_lock = if out.is_dir() {
        Some(FolderLock::try_acquire(out)?)
    } else {
        None
    };
    crate::exchange::in_staged_folder(out, |partial| {
        write_merged(partial, &shards, command, sections)
    })
}

/// Refuses an output folder a merge would spoil: one of the shards, or a folder holding
/// anything but an earlier merge of the same sweep (replaced whole). Before, an unrelated
/// sweep's records and same-named pictures were overwritten, and a shard could be its own
/// merge's output.
fn check_merge_out(out: &Path, shards: &[ShardFolder]) -> Result<(), HarnessError> {
    let refused = |what: String| -> HarnessError {
        SettingError::new("merge OUT", what, out.display().to_string()).into()
    };
    let o = mirrorbox_files::resolved(out);
    if let Some(s) = shards
        .iter()
        .find(|s| mirrorbox_files::resolved(&s.dir) == o)
    {
        return Err(refused(format!(
            "a folder apart from the shards (it is the shard {})",
            s.dir.display()
        )));
    }
    if out.exists() && !out.is_dir() {
        return Err(refused("a folder; this is a file".into()));
    }
    let Ok(mut entries) = std::fs::read_dir(out) else {
        return Ok(()); // made by the merge
    };
    if entries.next().is_none() {
        return Ok(());
    }
    let earlier = mirrorbox_report::read_sweep_info(out).ok();
    let same_merge = earlier.is_some_and(|info| {
        !info.shards.is_empty() && info.point_keys == shards[0].info.point_keys
    }) && !crate::SEQUENCE_FILES
        .iter()
        .chain(&crate::ADVICE_FILES)
        .any(|f| out.join(f).exists());
    if same_merge {
        return Ok(());
    }
    Err(refused(
        "a new or empty folder, or an earlier merge of these shards (it holds something else, \
         which the merge would mix its files with; a merge stopped half-way leaves such a \
         folder: remove it)"
            .into(),
    ))
}

/// The writing half of [`merge`], its inputs checked.
fn write_merged(
    out: &Path,
    shards: &[ShardFolder],
    command: &str,
    sections: &[mirrorbox_report::Section],
) -> Result<Merged, HarnessError> {
    let first = &shards[0];
    std::fs::create_dir_all(out.join("images")).map_err(|source| HarnessError::OutputFolder {
        path: out.to_path_buf(),
        source,
    })?;
    // (The stage `out` is locked by `in_staged_folder` while this writes it.)
    let mut by_key: HashMap<&str, Record> = HashMap::new();
    let mut copied: std::collections::HashSet<PathBuf> = std::collections::HashSet::new();
    for s in shards {
        let device = format!("{} on {}", s.info.adapter_description(), s.info.cpu);
        for r in &s.records {
            by_key.insert(
                r.key.as_str(),
                Record {
                    device: Some(device.clone()),
                    ..r.clone()
                },
            );
            for picture in crate::record_pictures(r) {
                let (from, to) = (s.dir.join(picture), out.join(picture));
                // Once per merge: points share pictures.
                if copied.insert(to.clone()) {
                    mirrorbox_files::write_atomically_with(&to, |tmp| {
                        std::fs::copy(&from, tmp)
                            .map(|_| ())
                            .map_err(|e| format!("cannot copy {}: {e}", from.display()))
                    })?;
                }
            }
        }
    }
    let records: Vec<Record> = first
        .info
        .point_keys
        .iter()
        .map(|k| by_key[k.as_str()].clone())
        .collect();
    let mut lines = String::new();
    for r in &records {
        lines.push_str(&serde_json::to_string(r)?);
        lines.push('\n');
    }
    write_atomically(&out.join("results.jsonl"), lines.as_bytes())?;
    let mut info = SweepInfo {
        command: command.to_string(),
        date: humantime::format_rfc3339_seconds(std::time::SystemTime::now()).to_string(),
        shard: None,
        shards: shards
            .iter()
            .map(|s| ShardInfo {
                shard: s.info.shard.clone().unwrap_or_default(),
                folder: s.dir.display().to_string(),
                date: s.info.date.clone(),
                cpu: s.info.cpu.clone(),
                device: s.info.adapter_description(),
                points: s.records.len(),
            })
            .collect(),
        ..first.info.clone()
    };
    sort_by_shard_number(&mut info.shards);
    let mut devices: Vec<String> = Vec::new();
    for s in &info.shards {
        let d = format!("{} on {}", s.device, s.cpu);
        if !devices.contains(&d) {
            devices.push(d);
        }
    }
    write_atomically(
        &out.join("sweep.json"),
        serde_json::to_string_pretty(&info)?.as_bytes(),
    )?;
    write_report(out, &info, &records, sections)?;
    Ok(Merged {
        shards: shards.len(),
        points: records.len(),
        devices,
    })
}

/// Shards in the order of their numbers: "10/12" after "2/12" (as text it came first).
fn sort_by_shard_number(shards: &mut [ShardInfo]) {
    let index = |s: &ShardInfo| {
        s.shard
            .split('/')
            .next()
            .and_then(|i| i.parse::<u32>().ok())
    };
    shards.sort_by(|a, b| index(a).cmp(&index(b)).then_with(|| a.shard.cmp(&b.shard)));
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_are_listed_by_number() {
        let mut shards: Vec<ShardInfo> = ["10/12", "2/12", "0/12"]
            .iter()
            .map(|s| ShardInfo {
                shard: s.to_string(),
                ..Default::default()
            })
            .collect();
        sort_by_shard_number(&mut shards);
        let order: Vec<&str> = shards.iter().map(|s| s.shard.as_str()).collect();
        assert_eq!(order, ["0/12", "2/12", "10/12"]);
    }
}
