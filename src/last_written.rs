//! The entries a pass through a short list wrote last, so that the next pass
//! through a list clears only those: the bookkeeping every step of a body in a
//! mostly empty mesh shares (the gathers' coverage, the lumped masses, the masked
//! rows' marks, the extension's roles, the affine-lumping marks).

/// The entries the last pass wrote: those of its list, or every entry when it
/// was not given one (or before the first pass).
#[derive(Debug, Clone, Default)]
pub(crate) struct LastWritten {
    list: Vec<u32>,
    listed: bool,
}

impl LastWritten {
    /// Nothing listed yet (any entry may be written); room for `n` entries, so
    /// that recording a list allocates nothing.
    pub(crate) fn with_capacity(n: usize) -> Self {
        LastWritten {
            list: Vec::with_capacity(n),
            listed: false,
        }
    }

    /// The entries the last pass may have written, of `n`: its list, ascending
    /// where it was, or `0..n`.
    pub(crate) fn each(&self, n: usize) -> impl Iterator<Item = usize> + '_ {
        let (all, list) = if self.listed {
            (0..0, &self.list[..])
        } else {
            (0..n, &[][..])
        };
        all.chain(list.iter().map(|&i| i as usize))
    }

    /// The last pass's list, if it had one.
    pub(crate) fn listed(&self) -> Option<&[u32]> {
        self.listed.then_some(&self.list[..])
    }

    /// This pass wrote the entries of `list` only.
    pub(crate) fn record(&mut self, list: &[u32]) {
        self.begin();
        self.list.extend_from_slice(list);
    }

    /// This pass writes the entries [`push`](Self::push)ed next, and no other.
    pub(crate) fn begin(&mut self) {
        self.list.clear();
        self.listed = true;
    }

    /// This pass wrote entry `i` (after [`begin`](Self::begin)).
    pub(crate) fn push(&mut self, i: usize) {
        self.list.push(i as u32);
    }

    /// This pass wrote every entry.
    pub(crate) fn record_all(&mut self) {
        self.listed = false;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_is_the_list_or_every_entry() {
        let mut w = LastWritten::with_capacity(5);
        assert_eq!(w.each(3).collect::<Vec<_>>(), [0, 1, 2]);
        assert_eq!(w.listed(), None);
        w.record(&[1, 4]);
        assert_eq!(w.each(5).collect::<Vec<_>>(), [1, 4]);
        assert_eq!(w.listed(), Some(&[1, 4][..]));
        w.record_all();
        assert_eq!(w.each(2).collect::<Vec<_>>(), [0, 1]);
        w.begin();
        w.push(3);
        assert_eq!(w.listed(), Some(&[3][..]));
    }
}
