//! Cache keys that name a shared value by its allocation.
//!
//! In: an `Arc<T>`. Out: an [`Identity`] that compares equal exactly to identities of the same
//! allocation. It holds a `Weak`, so the allocation cannot be freed and reused for another value
//! while the key exists (a raw pointer could, and a cache would then serve the old value's
//! entry for the new one), yet the value itself is dropped with its last `Arc`.

use std::sync::{Arc, Weak};

pub struct Identity<T>(Weak<T>);

impl<T> Identity<T> {
    pub fn of(value: &Arc<T>) -> Self {
        Identity(Arc::downgrade(value))
    }

    /// Whether `value` is the allocation this key names.
    pub fn is(&self, value: &Arc<T>) -> bool {
        std::ptr::eq(self.0.as_ptr(), Arc::as_ptr(value))
    }
}

impl<T> Clone for Identity<T> {
    fn clone(&self) -> Self {
        Identity(self.0.clone())
    }
}

impl<T> PartialEq for Identity<T> {
    fn eq(&self, other: &Self) -> bool {
        Weak::ptr_eq(&self.0, &other.0)
    }
}

impl<T> std::fmt::Debug for Identity<T> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Identity({:p})", self.0.as_ptr())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_one_allocation_and_keeps_it_from_reuse() {
        let a = Arc::new(vec![1u8; 64]);
        let b = Arc::new(vec![1u8; 64]);
        let key = Identity::of(&a);
        assert!(key.is(&a) && !key.is(&b));
        assert_eq!(key, Identity::of(&a.clone()));
        assert_ne!(key, Identity::of(&b));
        // The value goes with its last Arc; the allocation stays while the key does, so a new
        // value never lands where the key points.
        let address = Arc::as_ptr(&a);
        drop(a);
        let fresh: Vec<Arc<Vec<u8>>> = (0..64).map(|_| Arc::new(vec![2u8; 64])).collect();
        assert!(fresh
            .iter()
            .all(|f| Arc::as_ptr(f) != address && !key.is(f)));
    }
}
