//! An on-disk cache of accuracy targeting: the ErrP-to-noise ratio found for
//! a (decoder, protocol, EEG model, accuracy, seed), so that a sweep rerun,
//! resumed or sharded does not search it again.
//!
//! A cache entry is a small JSON file named by a hash of the full request,
//! which it also stores and compares on read: an entry for another request
//! is never used. An unreadable entry, or one whose ratio does not give
//! back the accuracy it records when evaluated again, is searched again and
//! rewritten.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

use errp_bci::TargetingResult;
use serde::{Deserialize, Serialize};

use errp_sim::Result;
use errp_sim::calibration::TargetingCache;
use errp_sim::write_atomic;

/// Where targeting results are kept (or nowhere).
#[derive(Debug, Clone, Default)]
pub struct TargetCache {
    dir: Option<PathBuf>,
    /// No directory because none could be found (not by choice).
    unset: bool,
    /// [`TargetCache::unwritable`] found the directory unwritable, and the
    /// user was told once: each entry's store failing is not told again.
    told_unwritable: Arc<AtomicBool>,
}

impl PartialEq for TargetCache {
    /// The same place (what was warned about does not matter).
    fn eq(&self, other: &Self) -> bool {
        self.dir == other.dir && self.unset == other.unset
    }
}

/// What a cache that keeps nothing costs, for the user.
const UNUSED: &str = "so every decoder's accuracy targeting is searched again on every run";

#[derive(Serialize, Deserialize)]
struct Entry {
    request: String,
    result: TargetingResult,
}

impl TargetCache {
    /// A cache in `dir` (created when first written).
    pub fn new(dir: impl Into<PathBuf>) -> Self {
        Self {
            dir: Some(dir.into()),
            ..Self::default()
        }
    }

    /// No cache: every targeting is searched.
    pub fn disabled() -> Self {
        Self::default()
    }

    /// The default place: `$ERRP_CACHE_DIR`, else `$XDG_CACHE_HOME/errp`,
    /// else `~/.cache/errp`, else none.
    pub fn default_location() -> Self {
        let env = |k: &str| {
            std::env::var_os(k)
                .filter(|v| !v.is_empty())
                .map(PathBuf::from)
        };
        let dir = env("ERRP_CACHE_DIR")
            .or_else(|| env("XDG_CACHE_HOME").map(|d| d.join("errp")))
            .or_else(|| env("HOME").map(|d| d.join(".cache").join("errp")));
        Self {
            unset: dir.is_none(),
            dir,
            ..Self::default()
        }
    }

    /// Why this cache will not keep anything, if it will not: no
    /// directory could be found, or the directory cannot be written (it is
    /// tried now, with a temporary file). A sweep runs without it, each
    /// targeting searched afresh.
    pub fn problem(&self) -> Option<String> {
        if self.unset {
            return Some(format!(
                "no targeting cache: $ERRP_CACHE_DIR, $XDG_CACHE_HOME and $HOME are all unset, \
                 {UNUSED} (give --cache DIR, or --no-cache to turn it off)"
            ));
        }
        self.unwritable("give another --cache DIR, or --no-cache")
    }

    /// Why the cache directory cannot be written, if it cannot, for the
    /// user, ending with `advice` (what to give instead, in the words of
    /// the front end): it is created if missing and tried now, with a
    /// temporary file. `None` also when there is no directory. The caller
    /// tells the user; the entries that then cannot be stored are not
    /// warned of one by one.
    pub fn unwritable(&self, advice: &str) -> Option<String> {
        let dir = self.dir.as_ref()?;
        let e = errp_sim::create_dir(dir)
            .and_then(|()| errp_sim::PendingFile::create(dir.join("write-test")).map(drop))
            .err()?;
        self.told_unwritable.store(true, Ordering::Relaxed);
        Some(format!(
            "the targeting cache cannot be written ({e}), {UNUSED} ({advice})"
        ))
    }

    /// The cache as a decoder's preparation uses it, each warning (an
    /// entry that did not verify and was searched again, an entry that
    /// could not be stored) told to `warn` as it happens, on the thread
    /// that found it.
    pub fn reporting<'a>(&'a self, warn: &'a (dyn Fn(&str) + Sync)) -> Reporting<'a> {
        Reporting { cache: self, warn }
    }

    /// The cache directory, if any.
    pub fn dir(&self) -> Option<&Path> {
        self.dir.as_deref()
    }

    fn store(path: &Path, entry: &Entry) -> Result<()> {
        if let Some(parent) = path.parent() {
            errp_sim::create_dir(parent)?;
        }
        let text = serde_json::to_string(entry).expect("a targeting result serialises");
        write_atomic(path, text.as_bytes())
    }
}

/// A [`TargetCache`] that tells its warnings as they happen
/// ([`TargetCache::reporting`]).
#[derive(Clone, Copy)]
pub struct Reporting<'a> {
    cache: &'a TargetCache,
    warn: &'a (dyn Fn(&str) + Sync),
}

impl TargetingCache for Reporting<'_> {
    /// Looks `request` up in `kind-HASH.json` under the cache directory
    /// (the request text is kept in the file and must match), and has
    /// `verify` evaluate the entry's ratio again: an entry whose figures do
    /// not come back is a miss, with a warning naming it. A miss searches
    /// and stores the result atomically, and a store that fails (with a
    /// warning) only costs the next run a search.
    fn get_or_search(
        &self,
        kind: &str,
        request: &str,
        search: &mut dyn FnMut() -> Result<TargetingResult>,
        verify: &mut dyn FnMut(&TargetingResult) -> Result<Option<String>>,
    ) -> Result<(TargetingResult, bool)> {
        let cache = self.cache;
        let Some(dir) = &cache.dir else {
            return Ok((search()?, false));
        };
        let request = format!("{kind} v1 {request}");
        let path = dir.join(format!(
            "{kind}-{:016x}.json",
            errp_bci::rng::fnv1a(&request)
        ));
        if let Ok(text) = read_entry(&path)
            && let Ok(entry) = serde_json::from_str::<Entry>(&text)
            && entry.request == request
        {
            let why = match verify(&entry.result) {
                Ok(None) => return Ok((entry.result, true)),
                Ok(Some(why)) => why,
                Err(e) => format!(
                    "evaluating its ratio {} fails ({e})",
                    errp_bci::ratio_text(entry.result.ratio)
                ),
            };
            (self.warn)(&format!(
                "the cached targeting {} is not what its search finds: {why}; searching again \
                 and replacing it",
                path.display()
            ));
        }
        let result = search()?;
        // A cache that cannot be written is not an error: the sweep goes on,
        // with a warning. (serde_json's `float_roundtrip` makes a stored
        // ratio read back bit for bit, so a hit gives what this miss gives.)
        let entry = Entry { request, result };
        if let Err(e) = TargetCache::store(&path, &entry)
            && !cache.told_unwritable.load(Ordering::Relaxed)
        {
            (self.warn)(&format!(
                "the targeting {} could not be stored in the cache ({e}); the results are \
                 the same, and the next sweep searches it again",
                path.display()
            ));
        }
        Ok((entry.result, false))
    }
}

/// The largest cache entry read (an entry is a request and a search's
/// few dozen steps: a few KiB).
const MAX_ENTRY_BYTES: u64 = 1 << 20;

/// The text of the entry at `path`: a regular file of at most
/// [`MAX_ENTRY_BYTES`] (anything else, a FIFO included, is a miss, found
/// without waiting).
fn read_entry(path: &Path) -> std::io::Result<String> {
    use std::io::Read;
    let mut text = String::new();
    errp_sim::open_regular(path)?
        .take(MAX_ENTRY_BYTES + 1)
        .read_to_string(&mut text)?;
    if text.len() as u64 > MAX_ENTRY_BYTES {
        return Err(std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            "over the size of a cache entry",
        ));
    }
    Ok(text)
}

#[cfg(test)]
mod tests {
    use super::*;
    use errp_bci::Accuracy;

    /// A cache whose warnings are kept, to be taken.
    struct Watched {
        cache: TargetCache,
        warnings: std::sync::Mutex<Vec<String>>,
    }

    impl Watched {
        fn new(dir: impl Into<PathBuf>) -> Self {
            Self {
                cache: TargetCache::new(dir),
                warnings: Default::default(),
            }
        }

        fn get_or_search(
            &self,
            kind: &str,
            request: &str,
            search: &mut dyn FnMut() -> Result<TargetingResult>,
            verify: &mut dyn FnMut(&TargetingResult) -> Result<Option<String>>,
        ) -> Result<(TargetingResult, bool)> {
            let keep = |w: &str| self.warnings.lock().unwrap().push(w.to_string());
            self.cache
                .reporting(&keep)
                .get_or_search(kind, request, search, verify)
        }

        fn take_warnings(&self) -> Vec<String> {
            std::mem::take(&mut *self.warnings.lock().unwrap())
        }
    }

    fn result(ratio: f64) -> TargetingResult {
        let accuracy = Accuracy {
            correct: 0.8,
            error: 0.7,
            n_correct: 320,
            n_error: 80,
        };
        TargetingResult {
            requested: 0.75,
            ratio,
            accuracy,
            steps: vec![errp_bci::TargetingStep { ratio, accuracy }],
        }
    }

    /// A verification that accepts every entry.
    fn ok(_: &TargetingResult) -> Result<Option<String>> {
        Ok(None)
    }

    fn scratch(name: &str) -> PathBuf {
        std::env::temp_dir().join(format!(
            "errp-cache-{name}-{:x}",
            errp_sim::host::random_suffix()
        ))
    }

    fn entries(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    #[test]
    fn a_hit_reads_back_bit_for_bit_and_a_damaged_entry_is_a_miss() {
        let dir = scratch("hit");
        let cache = Watched::new(&dir);
        let ratio = 0.1 + 0.2; // not a short decimal
        let (r, hit) = cache
            .get_or_search("k", "a", &mut || Ok(result(ratio)), &mut ok)
            .unwrap();
        assert!(!hit && r.ratio == ratio);
        let (r, hit) = cache
            .get_or_search("k", "a", &mut || panic!("a hit searches nothing"), &mut ok)
            .unwrap();
        assert!(hit && r.ratio.to_bits() == ratio.to_bits());
        // Another request is another entry.
        let (_, hit) = cache
            .get_or_search("k", "b", &mut || Ok(result(0.5)), &mut ok)
            .unwrap();
        assert!(!hit);
        // An entry cut short (or for another request) is searched again and
        // rewritten whole.
        let name = entries(&dir).into_iter().next().unwrap();
        let text = std::fs::read_to_string(dir.join(&name)).unwrap();
        std::fs::write(dir.join(&name), &text[..text.len() / 2]).unwrap();
        let mut searched = 0;
        for _ in 0..2 {
            let _ = cache
                .get_or_search(
                    "k",
                    "a",
                    &mut || {
                        searched += 1;
                        Ok(result(ratio))
                    },
                    &mut ok,
                )
                .unwrap();
            let _ = cache
                .get_or_search(
                    "k",
                    "b",
                    &mut || {
                        searched += 1;
                        Ok(result(0.5))
                    },
                    &mut ok,
                )
                .unwrap();
        }
        assert_eq!(searched, 1, "the damaged entry once, then hits");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// An entry that cannot be stored is a warning naming it, and the
    /// search's result is given all the same.
    #[test]
    fn an_entry_that_cannot_be_stored_is_a_warning() {
        let dir = scratch("store");
        let cache = Watched::new(&dir);
        let _ = cache
            .get_or_search("k", "a", &mut || Ok(result(0.25)), &mut ok)
            .unwrap();
        assert!(cache.take_warnings().is_empty());
        // A directory where the entry goes: read as a miss, not replaced.
        let name = entries(&dir).into_iter().next().unwrap();
        std::fs::remove_file(dir.join(&name)).unwrap();
        std::fs::create_dir(dir.join(&name)).unwrap();
        let (r, hit) = cache
            .get_or_search("k", "a", &mut || Ok(result(0.25)), &mut ok)
            .unwrap();
        assert!(!hit && r == result(0.25));
        let warnings = cache.take_warnings();
        assert_eq!(warnings.len(), 1, "{warnings:?}");
        assert!(
            warnings[0].contains(&name) && warnings[0].contains("could not be stored"),
            "{}",
            warnings[0]
        );
        assert!(dir.join(&name).is_dir());
        assert_eq!(entries(&dir), [name], "no temporary left behind");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Writers of one entry at once (threads here; hosts and processes on
    /// a shared file system alike) each write their own temporary: the
    /// entry is whole and nothing else is left.
    #[test]
    fn writers_of_one_entry_at_once_leave_it_whole() {
        let dir = scratch("writers");
        let cache = Watched::new(&dir);
        std::thread::scope(|s| {
            for _ in 0..8 {
                s.spawn(|| {
                    let (r, _) = cache
                        .get_or_search(
                            "k",
                            "same",
                            &mut || {
                                std::thread::sleep(std::time::Duration::from_millis(20));
                                Ok(result(0.42))
                            },
                            &mut ok,
                        )
                        .unwrap();
                    assert_eq!(r.ratio, 0.42);
                });
            }
        });
        let names = entries(&dir);
        assert_eq!(names.len(), 1, "{names:?}");
        let (r, hit) = cache
            .get_or_search("k", "same", &mut || panic!("whole: a hit"), &mut ok)
            .unwrap();
        assert!(hit && r == result(0.42));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_cache_that_cannot_be_kept_says_why() {
        assert!(TargetCache::disabled().problem().is_none());
        let writable = scratch("ok");
        assert!(TargetCache::new(&writable).problem().is_none());
        assert!(
            entries(&writable).is_empty(),
            "the write test leaves nothing"
        );
        let unwritable = Watched::new("/proc/errp-no-cache");
        let e = unwritable.cache.problem().unwrap();
        assert!(
            e.contains("/proc/errp-no-cache") && e.contains("--no-cache"),
            "{e}"
        );
        // Told once: its entries' stores failing are not warned of again,
        // while a store failing unannounced is.
        let search = |cache: &Watched| {
            let (r, hit) = cache
                .get_or_search("k", "a", &mut || Ok(result(0.5)), &mut ok)
                .unwrap();
            assert!(!hit && r == result(0.5));
            cache.take_warnings()
        };
        assert_eq!(search(&unwritable), Vec::<String>::new());
        let unannounced = search(&Watched::new("/proc/errp-no-cache"));
        assert!(
            unannounced.len() == 1 && unannounced[0].contains("could not be stored"),
            "{unannounced:?}"
        );
        let unset = TargetCache {
            dir: None,
            unset: true,
            ..TargetCache::default()
        };
        assert!(unset.problem().unwrap().contains("$HOME"));
        std::fs::remove_dir_all(&writable).unwrap();
    }

    /// An entry whose ratio was edited (x3, 0, 1e308), or whose figures do
    /// not come back when its ratio is evaluated again, is a miss with a
    /// warning naming the file, and is replaced by the search's result.
    #[test]
    fn an_entry_that_does_not_verify_is_a_miss_with_a_warning() {
        let dir = scratch("verify");
        let cache = Watched::new(&dir);
        let search = errp_bci::TargetingParams::default();
        // The "decoder": accuracy rises with the ratio; the true ratio of
        // the request is 0.3, which gives 75 %.
        let evaluate = |ratio: f64| {
            let mean = (0.5 + ratio / 1.2).min(0.99);
            if !ratio.is_finite() || ratio > 1e300 {
                return Err(errp_sim::SimError::Sweep("features not finite".into()));
            }
            Ok(Accuracy {
                correct: mean,
                error: mean,
                n_correct: 320,
                n_error: 80,
            })
        };
        let mut verify = |t: &TargetingResult| Ok(t.inconsistency(evaluate(t.ratio)?, &search));
        let truth = result(0.3);
        let mut truth_entry = truth.clone();
        truth_entry.accuracy = evaluate(0.3).unwrap();
        let (_, hit) = cache
            .get_or_search("k", "a", &mut || Ok(truth_entry.clone()), &mut verify)
            .unwrap();
        assert!(!hit);
        let (_, hit) = cache
            .get_or_search("k", "a", &mut || panic!("a hit"), &mut verify)
            .unwrap();
        assert!(hit, "a true entry verifies");
        assert!(cache.take_warnings().is_empty());
        let name = entries(&dir).into_iter().next().unwrap();
        let path = dir.join(&name);
        let original = std::fs::read_to_string(&path).unwrap();
        for tampered in ["0.8999999999999999", "0.0", "1e308", "-0.3"] {
            let text = original.replace("\"ratio\":0.3", &format!("\"ratio\":{tampered}"));
            assert_ne!(text, original);
            std::fs::write(&path, text).unwrap();
            let mut searched = false;
            let (r, hit) = cache
                .get_or_search(
                    "k",
                    "a",
                    &mut || {
                        searched = true;
                        Ok(truth_entry.clone())
                    },
                    &mut verify,
                )
                .unwrap();
            assert!(!hit && searched && r.ratio == 0.3, "ratio {tampered}");
            let warnings = cache.take_warnings();
            assert_eq!(warnings.len(), 1, "ratio {tampered}: {warnings:?}");
            assert!(warnings[0].contains(&name), "{}", warnings[0]);
            // Replaced: the next lookup is a hit again.
            let (_, hit) = cache
                .get_or_search("k", "a", &mut || panic!("replaced"), &mut verify)
                .unwrap();
            assert!(hit, "ratio {tampered}: the entry was replaced");
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
