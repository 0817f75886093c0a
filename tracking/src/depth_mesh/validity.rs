//! Structural checks of a triangulation, for tests and debug builds.

use spade::Triangulation;

use super::layer::Triangles;

/// Panics with a message if `triangles` is not a valid Delaunay triangulation: every inner
/// face counter-clockwise and non-degenerate, edges consistent with their twins, Euler's
/// formula, and no vertex strictly inside the circumcircle of a neighbouring face.
pub(crate) fn check_triangulation(triangles: &Triangles) {
    let num_vertices = triangles.num_vertices();
    if num_vertices < 3 || triangles.num_inner_faces() == 0 {
        return;
    }
    let num_edges = triangles.num_undirected_edges();
    let num_faces = triangles.num_all_faces();
    assert_eq!(
        num_vertices + num_faces,
        num_edges + 2,
        "Euler's formula V - E + F = 2 fails"
    );
    for edge in triangles.directed_edges() {
        assert_eq!(edge.rev().rev().fix(), edge.fix(), "twin of twin differs");
        assert_eq!(
            edge.next().from().fix(),
            edge.to().fix(),
            "next edge does not start at this edge's end"
        );
    }
    for face in triangles.inner_faces() {
        let [a, b, c] = face.positions();
        let orientation = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
        assert!(
            orientation > 0.0,
            "face {face:?} is not counter-clockwise ({orientation})"
        );
    }
    for edge in triangles.undirected_edges() {
        let e0 = edge.as_directed();
        let e1 = e0.rev();
        let (Some(opposite0), Some(opposite1)) = (e0.opposite_position(), e1.opposite_position())
        else {
            continue;
        };
        let [p, q] = e0.positions();
        assert!(
            !strictly_in_circle(p, q, opposite0, opposite1),
            "edge {:?} is not locally Delaunay",
            edge.fix()
        );
    }
}

/// Whether `d` lies strictly inside the circle through `a`, `b`, `c` (with a relative
/// tolerance for round-off; spade decides with exact predicates).
fn strictly_in_circle(
    a: spade::Point2<f64>,
    b: spade::Point2<f64>,
    c: spade::Point2<f64>,
    d: spade::Point2<f64>,
) -> bool {
    let rows = [a, b, c].map(|p| {
        let (x, y) = (p.x - d.x, p.y - d.y);
        [x, y, x * x + y * y]
    });
    let det = |r: [[f64; 3]; 3]| {
        r[0][0] * (r[1][1] * r[2][2] - r[1][2] * r[2][1])
            - r[0][1] * (r[1][0] * r[2][2] - r[1][2] * r[2][0])
            + r[0][2] * (r[1][0] * r[2][1] - r[1][1] * r[2][0])
    };
    let orientation = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    let scale: f64 = rows.iter().map(|r| r[2]).fold(0.0, f64::max);
    det(rows) * orientation.signum() > 1e-9 * scale * scale
}
