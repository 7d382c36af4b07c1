//! Packing the parts' images into atlas pages, and the `.atlas` text Spine's runtimes read.
//!
//! In: each part's image (straight-alpha RGBA8, placed on the shared canvas at its offset) and
//! its region rectangle on the canvas ([`RegionRect`]: the mesh's box plus a margin; it may
//! reach past the image, where the pixels are transparent). Out: [`AtlasPage`]s holding the regions, packed on shelves
//! (tallest first) with `padding_px` of transparent pixels between them, and the atlas text
//! (spine-format.md §12): page name, `size`, `filter`, `pma`, then per region its name and
//! `bounds: x, y, w, h` (top-left in page px, y down). Regions are never rotated or stripped:
//! the region *is* the trimmed image, so mesh uvs are relative to it.
//!
//! Premultiplied alpha: with [`AtlasOptions::premultiplied_alpha`] (the default) the page PNGs
//! hold premultiplied colour and the atlas says `pma: true`; otherwise straight colour and
//! `pma: false`. The flag must match the pixels or engines draw dark (or bright) fringes.

use super::mesh::RegionRect;
use super::SpineError;
use crate::geom::pack::{pack_shelves, ShelfLayout};
use image::{Rgba, RgbaImage};
use serde::{Deserialize, Serialize};

/// How the atlas is packed.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct AtlasOptions {
    /// Transparent px between regions and around the page's edge. Default 2.
    pub padding_px: u32,
    /// Largest page side (px); more regions open more pages. Default 4096.
    pub max_page_px: u32,
    /// Premultiply the pages' colour and say so in the atlas. Default true.
    pub premultiplied_alpha: bool,
}

impl Default for AtlasOptions {
    fn default() -> Self {
        AtlasOptions {
            padding_px: 2,
            max_page_px: 4096,
            premultiplied_alpha: true,
        }
    }
}

/// Where a region landed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PackedRegion {
    pub name: String,
    pub page: usize,
    /// Top-left corner in page px (y down).
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

/// One page: its PNG file name and pixels.
#[derive(Clone, Debug, PartialEq)]
pub struct AtlasPage {
    pub file_name: String,
    pub image: RgbaImage,
}

/// The packed atlas.
#[derive(Clone, Debug, PartialEq)]
pub struct Atlas {
    pub pages: Vec<AtlasPage>,
    pub regions: Vec<PackedRegion>,
    pub premultiplied_alpha: bool,
}

/// Packs `regions` (name, source image, the canvas position of the image's top-left pixel,
/// rectangle on the canvas) into pages named `{base}.png`, `{base}_2.png`, …
pub fn pack_atlas(
    base: &str,
    regions: &[(String, &RgbaImage, [i32; 2], RegionRect)],
    options: &AtlasOptions,
) -> Result<Atlas, SpineError> {
    let pad = options.padding_px;
    let max = options.max_page_px;
    for (name, _, _, r) in regions {
        if r.width + 2 * pad > max || r.height + 2 * pad > max {
            return Err(SpineError::RegionTooLarge {
                part: name.clone(),
                size: [r.width, r.height],
                max_page_px: max,
            });
        }
    }
    // Page width: the square that would hold every region, as a power of two, at least the
    // widest region and at most the page limit.
    let area: u64 = regions
        .iter()
        .map(|(_, _, _, r)| u64::from(r.width + pad) * u64::from(r.height + pad))
        .sum();
    let widest = regions
        .iter()
        .map(|(_, _, _, r)| r.width + 2 * pad)
        .max()
        .unwrap_or(1);
    let side = ((area as f64).sqrt().ceil() as u32)
        .max(widest)
        .next_power_of_two();
    let page_width = side.min(max);

    // Tallest first, then by name: deterministic shelves.
    let mut order: Vec<usize> = (0..regions.len()).collect();
    order.sort_by(|&a, &b| {
        regions[b]
            .3
            .height
            .cmp(&regions[a].3.height)
            .then(regions[a].0.cmp(&regions[b].0))
    });
    let sizes: Vec<(u64, u64)> = order
        .iter()
        .map(|&i| {
            (
                u64::from(regions[i].3.width),
                u64::from(regions[i].3.height),
            )
        })
        .collect();
    let layout = ShelfLayout {
        width: u64::from(page_width),
        padding: u64::from(pad),
        margin: u64::from(pad),
        page_height: Some(u64::from(max)),
    };
    let packing = pack_shelves(&sizes, &layout);
    let mut placed = vec![None; regions.len()];
    for (&i, p) in order.iter().zip(&packing.placements) {
        // Within a page, whose sides are at most `max` (a u32).
        placed[i] = Some((p.page, p.x as u32, p.y as u32));
    }
    let mut pages: Vec<AtlasPage> = packing
        .pages
        .iter()
        .map(|&[_, h]| h as u32)
        .enumerate()
        .map(|(k, h)| AtlasPage {
            file_name: if k == 0 {
                format!("{base}.png")
            } else {
                format!("{base}_{}.png", k + 1)
            },
            image: RgbaImage::new(page_width, h.max(1).next_power_of_two().min(max)),
        })
        .collect();
    let mut packed = Vec::with_capacity(regions.len());
    for (i, (name, source, [ox, oy], r)) in regions.iter().enumerate() {
        let Some((page, px, py)) = placed[i] else {
            continue;
        };
        let target = &mut pages[page].image;
        for dy in 0..r.height {
            for dx in 0..r.width {
                // Canvas px to the source image's px.
                let sx = r.x + i64::from(dx) - i64::from(*ox);
                let sy = r.y + i64::from(dy) - i64::from(*oy);
                let inside = sx >= 0
                    && sy >= 0
                    && sx < i64::from(source.width())
                    && sy < i64::from(source.height());
                if !inside {
                    continue;
                }
                let Rgba([cr, cg, cb, ca]) = *source.get_pixel(sx as u32, sy as u32);
                let pixel = if options.premultiplied_alpha {
                    let pm = |c: u8| ((u32::from(c) * u32::from(ca) + 127) / 255) as u8;
                    Rgba([pm(cr), pm(cg), pm(cb), ca])
                } else {
                    Rgba([cr, cg, cb, ca])
                };
                target.put_pixel(px + dx, py + dy, pixel);
            }
        }
        packed.push(PackedRegion {
            name: name.clone(),
            page,
            x: px,
            y: py,
            width: r.width,
            height: r.height,
        });
    }
    Ok(Atlas {
        pages,
        regions: packed,
        premultiplied_alpha: options.premultiplied_alpha,
    })
}

impl Atlas {
    /// The `.atlas` text (spine-format.md §12).
    pub fn text(&self) -> String {
        let mut out = String::new();
        for (k, page) in self.pages.iter().enumerate() {
            if k > 0 {
                out.push('\n');
            }
            out.push_str(&format!(
                "{}\nsize: {}, {}\nfilter: Linear, Linear\npma: {}\n",
                page.file_name,
                page.image.width(),
                page.image.height(),
                self.premultiplied_alpha
            ));
            for r in self.regions.iter().filter(|r| r.page == k) {
                out.push_str(&format!(
                    "{}\nbounds: {}, {}, {}, {}\n",
                    r.name, r.x, r.y, r.width, r.height
                ));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn solid(w: u32, h: u32, c: [u8; 4]) -> RgbaImage {
        RgbaImage::from_pixel(w, h, Rgba(c))
    }

    #[test]
    fn regions_do_not_overlap_and_keep_their_pixels() {
        let a = solid(40, 30, [255, 0, 0, 128]);
        let mut b = solid(40, 30, [0, 255, 0, 255]);
        b.put_pixel(0, 0, Rgba([0, 0, 255, 255]));
        let regions = vec![
            (
                "a".to_string(),
                &a,
                [0, 0],
                RegionRect {
                    x: -2,
                    y: 5,
                    width: 12,
                    height: 20,
                },
            ),
            (
                // b's image lies at (10, 10) on the canvas: the region starts at its corner.
                "b".to_string(),
                &b,
                [10, 10],
                RegionRect {
                    x: 10,
                    y: 10,
                    width: 25,
                    height: 8,
                },
            ),
        ];
        let atlas = pack_atlas("rig", &regions, &AtlasOptions::default()).unwrap();
        assert_eq!(atlas.pages.len(), 1);
        let (ra, rb) = (&atlas.regions[0], &atlas.regions[1]);
        let overlap = ra.x < rb.x + rb.width
            && rb.x < ra.x + ra.width
            && ra.y < rb.y + rb.height
            && rb.y < ra.y + ra.height;
        assert!(!overlap);
        let page = &atlas.pages[0].image;
        // Column 0 and 1 of region a lie left of the canvas: transparent. Column 2 is red,
        // premultiplied: 255·128/255 = 128.
        assert_eq!(page.get_pixel(ra.x, ra.y).0, [0, 0, 0, 0]);
        assert_eq!(page.get_pixel(ra.x + 2, ra.y).0, [128, 0, 0, 128]);
        assert_eq!(
            page.get_pixel(rb.x, rb.y).0,
            [0, 0, 255, 255],
            "b's corner pixel"
        );
        assert_eq!(page.get_pixel(rb.x + 1, rb.y).0, [0, 255, 0, 255]);
        let text = atlas.text();
        assert!(text.starts_with("rig.png\nsize: "), "{text}");
        assert!(text.contains("pma: true\n"));
        assert!(text.contains(&format!("a\nbounds: {}, {}, 12, 20\n", ra.x, ra.y)));
        // Every colour channel is at most alpha: consistent with pma: true.
        assert!(page.pixels().all(|p| p.0[..3].iter().all(|&c| c <= p.0[3])));
    }

    #[test]
    fn too_large_a_region_is_an_error_and_many_regions_open_pages() {
        let img = solid(10, 10, [1, 2, 3, 4]);
        let big = vec![(
            "big".to_string(),
            &img,
            [0, 0],
            RegionRect {
                x: 0,
                y: 0,
                width: 5000,
                height: 10,
            },
        )];
        assert!(matches!(
            pack_atlas("r", &big, &AtlasOptions::default()),
            Err(SpineError::RegionTooLarge { .. })
        ));
        let options = AtlasOptions {
            max_page_px: 64,
            ..Default::default()
        };
        let many: Vec<_> = (0..6)
            .map(|i| {
                (
                    format!("r{i}"),
                    &img,
                    [0, 0],
                    RegionRect {
                        x: 0,
                        y: 0,
                        width: 30,
                        height: 30,
                    },
                )
            })
            .collect();
        let atlas = pack_atlas("r", &many, &options).unwrap();
        assert!(atlas.pages.len() >= 2);
        assert_eq!(atlas.pages[1].file_name, "r_2.png");
        for r in &atlas.regions {
            let page = &atlas.pages[r.page].image;
            assert!(r.x + r.width <= page.width() && r.y + r.height <= page.height());
        }
    }
}
