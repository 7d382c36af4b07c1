//! Shelf packing of rectangles: the one packer behind the sprite sheet
//! ([`crate::io::sequence`]) and the Spine atlas pages ([`crate::export::spine`]).
//!
//! In: rectangle sizes (px) in the order to place them, and a [`ShelfLayout`]. Out: each
//! rectangle's page and top-left corner, and each page's used extent. Rectangles go left to
//! right on a shelf; the next starts a new shelf, below the tallest rectangle of the current one,
//! when it would pass the width; with a page height, the next starts a new page when it would
//! pass that. Sizes are u64 so that absurd inputs cannot overflow.

/// Where and how rectangles are packed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShelfLayout {
    /// Widest a shelf may run, margins included (px). A rectangle wider than that still gets
    /// a shelf of its own.
    pub width: u64,
    /// Between neighbouring rectangles, across and down (px).
    pub padding: u64,
    /// Around each page's edge (px): the first rectangle sits at (margin, margin), and a shelf
    /// and a page end `margin` before the width and the page height.
    pub margin: u64,
    /// Tallest a page may be, margins included (px); `None`: one page, as tall as it takes.
    pub page_height: Option<u64>,
}

/// A rectangle's place: its page and its top-left corner on it (px, y down).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placement {
    pub page: usize,
    pub x: u64,
    pub y: u64,
}

/// What [`pack_shelves`] gives.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ShelfPacking {
    /// One per rectangle, in the order given.
    pub placements: Vec<Placement>,
    /// Each page's used (width, height): the farthest rectangle edge plus the margin. There is
    /// always a first page, (0, 0) when nothing was packed (plus the margin when there is one).
    pub pages: Vec<[u64; 2]>,
}

/// Packs `sizes` (width, height) on shelves, in order, as `layout` says.
pub fn pack_shelves(sizes: &[(u64, u64)], layout: &ShelfLayout) -> ShelfPacking {
    let ShelfLayout {
        width,
        padding,
        margin,
        page_height,
    } = *layout;
    let (mut page, mut x, mut y, mut shelf) = (0usize, margin, margin, 0u64);
    let mut pages = vec![[0u64; 2]];
    let mut placements = Vec::with_capacity(sizes.len());
    for &(w, h) in sizes {
        if x > margin && x + w + margin > width {
            x = margin;
            y += shelf + padding;
            shelf = 0;
        }
        if page_height.is_some_and(|max| y > margin && y + h + margin > max) {
            page += 1;
            pages.push([0, 0]);
            x = margin;
            y = margin;
            shelf = 0;
        }
        placements.push(Placement { page, x, y });
        pages[page][0] = pages[page][0].max(x + w + margin);
        pages[page][1] = pages[page][1].max(y + h + margin);
        x += w + padding;
        shelf = shelf.max(h);
    }
    ShelfPacking { placements, pages }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(page: usize, x: u64, y: u64) -> Placement {
        Placement { page, x, y }
    }

    #[test]
    fn shelves_fill_left_to_right_then_down() {
        let layout = ShelfLayout {
            width: 10,
            padding: 1,
            margin: 0,
            page_height: None,
        };
        let packed = pack_shelves(&[(4, 3), (4, 5), (4, 2), (12, 1)], &layout);
        // 4 + 1 + 4 = 9 fits in 10; the third would end at 14: a new shelf below the taller
        // (5) plus padding; the over-wide one gets a shelf of its own.
        assert_eq!(
            packed.placements,
            [at(0, 0, 0), at(0, 5, 0), at(0, 0, 6), at(0, 0, 9)]
        );
        assert_eq!(packed.pages, [[12, 10]]);
        assert_eq!(pack_shelves(&[], &layout).pages, [[0, 0]]);
    }

    #[test]
    fn margins_frame_each_page_and_full_pages_open_new_ones() {
        let layout = ShelfLayout {
            width: 16,
            padding: 2,
            margin: 2,
            page_height: Some(16),
        };
        let packed = pack_shelves(&[(6, 6), (6, 6), (6, 6), (6, 6), (6, 6)], &layout);
        // A second on the shelf would end at 2 + 6 + 2 + 6 + 2 = 18 > 16, and so would a
        // second shelf on the page: one rectangle a page.
        assert_eq!(packed.placements[0], at(0, 2, 2));
        assert_eq!(packed.placements[1], at(1, 2, 2));
        assert_eq!(packed.pages.len(), 5);
        assert!(packed.pages.iter().all(|&p| p == [10, 10]));
        let roomy = ShelfLayout {
            width: 18,
            page_height: Some(18),
            ..layout
        };
        let packed = pack_shelves(&[(6, 6), (6, 6), (6, 6), (6, 6), (6, 6)], &roomy);
        assert_eq!(
            packed.placements,
            [
                at(0, 2, 2),
                at(0, 10, 2),
                at(0, 2, 10),
                at(0, 10, 10),
                at(1, 2, 2)
            ]
        );
        assert_eq!(packed.pages, [[18, 18], [10, 10]]);
    }
}
