//! A result that a known number of callers of one process need, computed once: the
//! first caller computes it (a caller arriving meanwhile waits for it), every caller gets
//! a copy, and the entry is forgotten after the last one. The driver shares the probe
//! group of an adversarial twin pair this way: the probe group and its twin group both
//! need the probe's specs (`driver::produce_planned_group`).
//!
//! Pure memoisation: a value is only ever computed by the caller's own function of the
//! key, so what a caller gets does not depend on which caller computed it, nor on the
//! order or the thread the callers run in.

use std::sync::{Arc, Mutex, OnceLock};

struct Entry<K, V> {
    key: K,
    value: Arc<OnceLock<V>>,
    /// Callers that have asked so far.
    taken: u32,
}

/// Values by key, each for `takers` callers; at most `capacity` entries are kept (the
/// oldest is dropped first: its remaining callers then compute it themselves).
pub struct Shared<K, V> {
    entries: Mutex<Vec<Entry<K, V>>>,
    capacity: usize,
}

impl<K: PartialEq, V: Clone> Shared<K, V> {
    pub const fn new(capacity: usize) -> Shared<K, V> {
        Shared {
            entries: Mutex::new(Vec::new()),
            capacity,
        }
    }

    /// The value for `key`: `compute()`'s result, computed by the first of the `takers`
    /// callers that ask for `key`.
    pub fn get(&self, key: K, takers: u32, compute: impl FnOnce() -> V) -> V {
        let value = {
            let mut entries = self.entries.lock().unwrap_or_else(|e| e.into_inner());
            let i = match entries.iter().position(|e| e.key == key) {
                Some(i) => i,
                None => {
                    if entries.len() >= self.capacity.max(1) {
                        entries.remove(0);
                    }
                    entries.push(Entry {
                        key,
                        value: Arc::default(),
                        taken: 0,
                    });
                    entries.len() - 1
                }
            };
            let entry = &mut entries[i];
            entry.taken += 1;
            let value = entry.value.clone();
            if entry.taken >= takers {
                entries.remove(i);
            }
            value
        };
        value.get_or_init(compute).clone()
    }

    /// Entries held (values some caller has yet to take).
    pub fn len(&self) -> usize {
        self.entries.lock().unwrap_or_else(|e| e.into_inner()).len()
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicU32, Ordering};

    #[test]
    fn computed_once_for_its_takers_then_forgotten() {
        let shared: Shared<u32, String> = Shared::new(4);
        let runs = AtomicU32::new(0);
        let compute = |k: u32| {
            runs.fetch_add(1, Ordering::SeqCst);
            format!("value {k}")
        };
        assert_eq!(shared.get(7, 2, || compute(7)), "value 7");
        assert_eq!(shared.len(), 1);
        assert_eq!(shared.get(7, 2, || compute(7)), "value 7");
        assert_eq!(runs.load(Ordering::SeqCst), 1);
        assert!(shared.is_empty());
        // Asked again after its takers: computed afresh.
        assert_eq!(shared.get(7, 2, || compute(7)), "value 7");
        assert_eq!(runs.load(Ordering::SeqCst), 2);
    }

    #[test]
    fn the_oldest_entry_gives_way_beyond_capacity() {
        let shared: Shared<u32, u32> = Shared::new(2);
        for k in 0..3 {
            shared.get(k, 2, || k * 10);
        }
        assert_eq!(shared.len(), 2);
        // Key 0 was dropped: its second taker computes it (same value).
        let mut computed = false;
        assert_eq!(
            shared.get(0, 2, || {
                computed = true;
                0
            }),
            0
        );
        assert!(computed);
    }

    #[test]
    fn concurrent_takers_get_one_computation() {
        let shared: Shared<u32, u64> = Shared::new(8);
        let runs = AtomicU32::new(0);
        std::thread::scope(|s| {
            let handles: Vec<_> = (0..4)
                .map(|_| {
                    s.spawn(|| {
                        shared.get(1, 4, || {
                            runs.fetch_add(1, Ordering::SeqCst);
                            std::thread::sleep(std::time::Duration::from_millis(20));
                            42
                        })
                    })
                })
                .collect();
            for h in handles {
                assert_eq!(h.join().unwrap(), 42);
            }
        });
        assert_eq!(runs.load(Ordering::SeqCst), 1);
        assert!(shared.is_empty());
    }
}
