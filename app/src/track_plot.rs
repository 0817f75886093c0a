//! Top view (x–y of the ground-truth frame) of the true trajectory and the aligned estimate.

use plotters::prelude::*;
use std::path::Path;
use sylva_tracking::report::TrackReport;

/// A polyline in plot coordinates (metres).
type Polyline = Vec<(f64, f64)>;

/// Draws the plot; without ground truth, the estimated positions alone.
pub fn draw(report: &TrackReport, path: &Path) -> anyhow::Result<()> {
    let (truth, estimate): (Polyline, Polyline) = if report.aligned.is_empty() {
        let est = report
            .trajectory
            .iter()
            .filter_map(|r| r.position)
            .map(|p| (p[0], p[2]))
            .collect();
        (Vec::new(), est)
    } else {
        report
            .aligned
            .iter()
            .map(|(t, e)| ((t[0], t[1]), (e[0], e[1])))
            .unzip()
    };
    let all = truth.iter().chain(&estimate);
    let (mut x0, mut x1, mut y0, mut y1) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for &(x, y) in all {
        (x0, x1, y0, y1) = (x0.min(x), x1.max(x), y0.min(y), y1.max(y));
    }
    if x0 > x1 {
        anyhow::bail!("no tracked frames to plot");
    }
    let pad = 0.05 * (x1 - x0).max(y1 - y0).max(1e-3);
    const SIDE: u32 = 800;
    let mut rgb = vec![0u8; (SIDE * SIDE * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut rgb, (SIDE, SIDE)).into_drawing_area();
        root.fill(&WHITE)?;
        let mut chart = ChartBuilder::on(&root)
            .margin(20)
            .build_cartesian_2d((x0 - pad)..(x1 + pad), (y0 - pad)..(y1 + pad))?;
        chart.draw_series(LineSeries::new(truth, BLACK.stroke_width(2)))?;
        chart.draw_series(LineSeries::new(estimate, RED.stroke_width(2)))?;
        root.present()?;
    }
    // Drawn in memory, written atomically like every other output.
    let image = image::RgbImage::from_raw(SIDE, SIDE, rgb)
        .ok_or_else(|| anyhow::anyhow!("the plot buffer has the wrong size"))?;
    crate::outputs::write_png(&image, path)
}
