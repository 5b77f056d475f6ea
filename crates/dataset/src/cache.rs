//! A small thread-safe cache that computes each value once, even when several threads ask
//! for it at the same time, and keeps the most recently inserted entries.

use std::collections::{HashMap, VecDeque};
use std::hash::Hash;
use std::sync::{Arc, Mutex, OnceLock};

/// The cells by key, and the keys from oldest to newest.
type Cells<K, V> = (HashMap<K, Arc<OnceLock<V>>>, VecDeque<K>);

/// Values of type `V` by key, computed on first use; at most `capacity` kept.
pub struct KeyedCache<K, V> {
    capacity: usize,
    inner: Mutex<Cells<K, V>>,
}

impl<K: Hash + Eq + Clone, V: Clone> KeyedCache<K, V> {
    /// An empty cache keeping at most `capacity` (at least 1) values.
    pub fn new(capacity: usize) -> Self {
        Self {
            capacity: capacity.max(1),
            inner: Mutex::new((HashMap::new(), VecDeque::new())),
        }
    }

    /// The value of `key`, computing it with `init` if it is not cached. Threads asking for
    /// the same key while it is computed wait for that one computation.
    pub fn get_or_init(&self, key: &K, init: impl FnOnce() -> V) -> V {
        let cell = {
            let mut guard = self.inner.lock().unwrap_or_else(|p| p.into_inner());
            let (map, order) = &mut *guard;
            if let Some(cell) = map.get(key) {
                cell.clone()
            } else {
                let cell = Arc::new(OnceLock::new());
                map.insert(key.clone(), cell.clone());
                order.push_back(key.clone());
                while order.len() > self.capacity {
                    if let Some(old) = order.pop_front() {
                        map.remove(&old);
                    }
                }
                cell
            }
        };
        cell.get_or_init(init).clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::atomic::{AtomicUsize, Ordering};

    #[test]
    fn computes_once_and_evicts_oldest() {
        let cache = KeyedCache::new(2);
        let calls = AtomicUsize::new(0);
        let get = |k: u32| {
            cache.get_or_init(&k, || {
                calls.fetch_add(1, Ordering::SeqCst);
                k * 10
            })
        };
        std::thread::scope(|s| {
            for _ in 0..4 {
                s.spawn(|| assert_eq!(get(1), 10));
            }
        });
        assert_eq!(calls.load(Ordering::SeqCst), 1);
        assert_eq!(get(2), 20);
        assert_eq!(get(3), 30); // evicts 1
        assert_eq!(get(1), 10);
        assert_eq!(calls.load(Ordering::SeqCst), 4);
    }
}
