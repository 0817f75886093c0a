//! The user's marks on the real tree: a tap on the trunk base and the crown's outline traced in
//! one or more frames. `MARKS.json` is
//! `{"base": {"frame": I, "pixel": [u, v]}, "crown": [{"frame": J, "outline": [[u, v], ...]}, ...]}`
//! (frames are 0-based indices in the footage's `rgb.txt` order; pixels in the distorted image as
//! stored). Every check names the mark it refuses (`base`, `crown[1]`).

use std::path::Path;

use glam::DVec2;
use serde::{Deserialize, Serialize};

/// The trunk-base tap.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BaseMark {
    pub frame: usize,
    pub pixel: [f64; 2],
}

/// One traced crown outline (closed implicitly).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CrownMark {
    pub frame: usize,
    pub outline: Vec<[f64; 2]>,
}

/// Everything the user marked.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Marks {
    pub base: BaseMark,
    pub crown: Vec<CrownMark>,
}

/// A mark that cannot be used; `mark` names it (`base`, `crown[1]`).
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum MarksError {
    #[error("cannot read the marks file {path}: {reason}")]
    Read { path: String, reason: String },
    #[error("the marks file {path} is not valid marks JSON: {reason}")]
    Parse { path: String, reason: String },
    #[error("the marks have no crown outline: trace the crown in at least one frame")]
    NoOutline,
    #[error("{mark}: frame {frame} is past the end of the footage ({num_frames} frames, 0 to {last})", last = num_frames.saturating_sub(1))]
    FramePastEnd {
        mark: String,
        frame: usize,
        num_frames: usize,
    },
    #[error("{mark}: pixel ({u}, {v}) is not a finite point inside the {width} x {height} image")]
    PixelOutside {
        mark: String,
        u: f64,
        v: f64,
        width: u32,
        height: u32,
    },
    #[error("{mark}: an outline needs at least 3 points, this one has {num_points}")]
    TooFewPoints { mark: String, num_points: usize },
    #[error("{mark}: the outline crosses itself (edge {first} meets edge {second})")]
    SelfCrossing {
        mark: String,
        first: usize,
        second: usize,
    },
    #[error("{mark}: the outline encloses no area")]
    NoArea { mark: String },
    #[error(
        "the crown outlines {marks} share no space above the ground: they do not trace the same tree"
    )]
    EmptyHull { marks: String },
    #[error("{mark}: frame {frame} was not tracked (tracking was lost or not yet started there)")]
    FrameNotTracked { mark: String, frame: usize },
    #[error(
        "{mark}: the pixel ({u}, {v}) in frame {frame} does not look at the ground plane (it is above the horizon or too far away)"
    )]
    BaseOffGround {
        mark: String,
        frame: usize,
        u: f64,
        v: f64,
    },
}

/// Outlines may run a little past the image border (a finger at the edge); this far, pixels.
const OUTLINE_MARGIN_PX: f64 = 64.0;

impl CrownMark {
    pub fn points(&self) -> Vec<DVec2> {
        self.outline
            .iter()
            .map(|&[u, v]| DVec2::new(u, v))
            .collect()
    }
}

impl Marks {
    /// Reads and parses `path` (not yet checked against the footage: see [`Marks::validate`]).
    pub fn from_file(path: &Path) -> Result<Marks, MarksError> {
        let text = std::fs::read_to_string(path).map_err(|e| MarksError::Read {
            path: path.display().to_string(),
            reason: e.to_string(),
        })?;
        serde_json::from_str(&text).map_err(|e| MarksError::Parse {
            path: path.display().to_string(),
            reason: e.to_string(),
        })
    }

    /// Checks every mark against footage of `num_frames` frames of `width` × `height`.
    pub fn validate(&self, num_frames: usize, width: u32, height: u32) -> Result<(), MarksError> {
        if self.crown.is_empty() {
            return Err(MarksError::NoOutline);
        }
        let frame_ok = |mark: &str, frame: usize| {
            if frame < num_frames {
                Ok(())
            } else {
                Err(MarksError::FramePastEnd {
                    mark: mark.to_owned(),
                    frame,
                    num_frames,
                })
            }
        };
        let inside = |mark: &str, [u, v]: [f64; 2], margin: f64| {
            let ok = u.is_finite()
                && v.is_finite()
                && (-margin..=width as f64 + margin).contains(&u)
                && (-margin..=height as f64 + margin).contains(&v);
            if ok {
                Ok(())
            } else {
                Err(MarksError::PixelOutside {
                    mark: mark.to_owned(),
                    u,
                    v,
                    width,
                    height,
                })
            }
        };
        frame_ok("base", self.base.frame)?;
        inside("base", self.base.pixel, 0.0)?;
        for (index, crown) in self.crown.iter().enumerate() {
            let mark = format!("crown[{index}]");
            frame_ok(&mark, crown.frame)?;
            for &point in &crown.outline {
                inside(&mark, point, OUTLINE_MARGIN_PX)?;
            }
            check_outline(&mark, &crown.points())?;
        }
        Ok(())
    }
}

/// At least three points, no two edges crossing, some area.
fn check_outline(mark: &str, points: &[DVec2]) -> Result<(), MarksError> {
    let n = points.len();
    if n < 3 {
        return Err(MarksError::TooFewPoints {
            mark: mark.to_owned(),
            num_points: n,
        });
    }
    for i in 0..n {
        for j in i + 1..n {
            // Neighbouring edges share a vertex; that is not a crossing.
            if j == i + 1 || (i == 0 && j == n - 1) {
                continue;
            }
            let (a, b) = (points[i], points[(i + 1) % n]);
            let (c, d) = (points[j], points[(j + 1) % n]);
            if segments_cross(a, b, c, d) {
                return Err(MarksError::SelfCrossing {
                    mark: mark.to_owned(),
                    first: i,
                    second: j,
                });
            }
        }
    }
    if polygon_area(points).abs() < 1.0 {
        return Err(MarksError::NoArea {
            mark: mark.to_owned(),
        });
    }
    Ok(())
}

/// Signed area (shoelace), square pixels.
pub fn polygon_area(points: &[DVec2]) -> f64 {
    let n = points.len();
    0.5 * (0..n)
        .map(|i| points[i].perp_dot(points[(i + 1) % n]))
        .sum::<f64>()
}

fn segments_cross(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let orient = |p: DVec2, q: DVec2, r: DVec2| (q - p).perp_dot(r - p);
    let (d1, d2) = (orient(c, d, a), orient(c, d, b));
    let (d3, d4) = (orient(a, b, c), orient(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    // Touching or overlapping (collinear) edges count as crossing too.
    let on = |p: DVec2, q: DVec2, r: DVec2| {
        orient(p, q, r).abs() < 1e-9
            && r.x >= p.x.min(q.x)
            && r.x <= p.x.max(q.x)
            && r.y >= p.y.min(q.y)
            && r.y <= p.y.max(q.y)
    };
    on(c, d, a) || on(c, d, b) || on(a, b, c) || on(a, b, d)
}

/// Whether `p` lies inside the closed polygon (even–odd rule).
pub fn polygon_contains(points: &[DVec2], p: DVec2) -> bool {
    let n = points.len();
    let mut inside = false;
    let mut j = n.wrapping_sub(1);
    for i in 0..n {
        let (a, b) = (points[i], points[j]);
        if (a.y > p.y) != (b.y > p.y) && p.x < (b.x - a.x) * (p.y - a.y) / (b.y - a.y) + a.x {
            inside = !inside;
        }
        j = i;
    }
    inside
}

#[cfg(test)]
mod tests {
    use super::*;

    fn marks(outline: Vec<[f64; 2]>) -> Marks {
        Marks {
            base: BaseMark {
                frame: 0,
                pixel: [320.0, 400.0],
            },
            crown: vec![CrownMark { frame: 3, outline }],
        }
    }

    #[test]
    fn a_square_outline_is_accepted() {
        let m = marks(vec![
            [100.0, 100.0],
            [200.0, 100.0],
            [200.0, 200.0],
            [100.0, 200.0],
        ]);
        assert_eq!(m.validate(10, 640, 480), Ok(()));
    }

    #[test]
    fn a_bow_tie_outline_is_refused_as_self_crossing() {
        let m = marks(vec![
            [100.0, 100.0],
            [200.0, 200.0],
            [200.0, 100.0],
            [100.0, 200.0],
        ]);
        let error = m.validate(10, 640, 480).unwrap_err();
        assert!(matches!(error, MarksError::SelfCrossing { .. }), "{error}");
        assert!(error.to_string().starts_with("crown[0]:"), "{error}");
    }

    #[test]
    fn two_points_are_not_an_outline() {
        let m = marks(vec![[100.0, 100.0], [200.0, 200.0]]);
        assert!(matches!(
            m.validate(10, 640, 480),
            Err(MarksError::TooFewPoints { num_points: 2, .. })
        ));
    }

    #[test]
    fn a_frame_past_the_end_names_the_mark_and_the_length() {
        let mut m = marks(vec![[100.0, 100.0], [200.0, 100.0], [150.0, 200.0]]);
        m.base.frame = 12;
        let error = m.validate(10, 640, 480).unwrap_err();
        assert_eq!(
            error.to_string(),
            "base: frame 12 is past the end of the footage (10 frames, 0 to 9)"
        );
    }

    #[test]
    fn the_point_in_polygon_test_follows_the_even_odd_rule() {
        let square = [
            DVec2::new(0.0, 0.0),
            DVec2::new(10.0, 0.0),
            DVec2::new(10.0, 10.0),
            DVec2::new(0.0, 10.0),
        ];
        assert!(polygon_contains(&square, DVec2::new(5.0, 5.0)));
        assert!(!polygon_contains(&square, DVec2::new(15.0, 5.0)));
        assert!((polygon_area(&square) - 100.0).abs() < 1e-9);
    }
}
