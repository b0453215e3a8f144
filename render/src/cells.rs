//! Grids of marked cells as rectangles: the redraw and post-process regions
//! (`regions`, `tiles`) and the cells FXAA filters again (`fxaa::apply_changed`), and
//! the rectangle arithmetic they share.

/// Rectangles (pixels) covering the marked tiles (`cols` × `rows`, row-major, side
/// `tile`): each tile row's runs, runs with the same span in consecutive rows stacked
/// into one rectangle.
pub(crate) fn runs_to_rects(
    marked: &[bool],
    cols: u32,
    rows: u32,
    tile: u32,
    width: u32,
    height: u32,
) -> Vec<[u32; 4]> {
    // Open rectangles in tile units: (first column, end column, first row, end row).
    let mut done: Vec<[u32; 4]> = Vec::new();
    let mut open: Vec<[u32; 4]> = Vec::new();
    for ty in 0..rows {
        let mut runs = Vec::new();
        let mut tx = 0;
        while tx < cols {
            if marked[(ty * cols + tx) as usize] {
                let start = tx;
                while tx < cols && marked[(ty * cols + tx) as usize] {
                    tx += 1;
                }
                runs.push((start, tx));
            } else {
                tx += 1;
            }
        }
        let mut next = Vec::new();
        for (c0, c1) in runs {
            match open.iter().position(|o| o[0] == c0 && o[1] == c1) {
                Some(i) => {
                    let mut o = open.swap_remove(i);
                    o[3] = ty + 1;
                    next.push(o);
                }
                None => next.push([c0, c1, ty, ty + 1]),
            }
        }
        done.append(&mut open);
        open = next;
    }
    done.append(&mut open);
    done.into_iter()
        .map(|[c0, c1, r0, r1]| {
            let (x0, y0) = (c0 * tile, r0 * tile);
            let (x1, y1) = ((c1 * tile).min(width), (r1 * tile).min(height));
            [x0, y0, x1 - x0, y1 - y0]
        })
        .collect()
}

/// The area of a rectangle (x, y, width, height) in pixels.
pub(crate) fn rect_area(r: [u32; 4]) -> u64 {
    r[2] as u64 * r[3] as u64
}

/// The bounding rectangle of two (x, y, width, height).
pub(crate) fn rect_union(a: [u32; 4], b: [u32; 4]) -> [u32; 4] {
    let (x0, y0) = (a[0].min(b[0]), a[1].min(b[1]));
    let (x1, y1) = (
        (a[0] + a[2]).max(b[0] + b[2]),
        (a[1] + a[3]).max(b[1] + b[3]),
    );
    [x0, y0, x1 - x0, y1 - y0]
}

/// Whether two rectangles (x, y, width, height) share a pixel.
pub(crate) fn rects_meet(a: [u32; 4], b: [u32; 4]) -> bool {
    a[0] < b[0] + b[2] && b[0] < a[0] + a[2] && a[1] < b[1] + b[3] && b[1] < a[1] + a[3]
}
