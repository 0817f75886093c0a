//! The "Advanced" panel's direct-manipulation widgets (Longay 2014 §5.4.2): the α/β/γ
//! triangle, the tropism arrow (θ) and the gravimorphism ellipse.

use egui::{Color32, Pos2, Response, Sense, Stroke, Ui, Vec2, WidgetInfo};

/// Barycentric coordinates of `p` in triangle `abc`, clamped onto the triangle (sum 1, each ≥ 0).
pub fn barycentric_clamped(p: Pos2, [a, b, c]: [Pos2; 3]) -> [f32; 3] {
    let v0 = b - a;
    let v1 = c - a;
    let v2 = p - a;
    let den = v0.x * v1.y - v1.x * v0.y;
    if den.abs() < 1e-9 {
        return [1.0, 0.0, 0.0];
    }
    let beta = (v2.x * v1.y - v1.x * v2.y) / den;
    let gamma = (v0.x * v2.y - v2.x * v0.y) / den;
    let w = [1.0 - beta - gamma, beta, gamma].map(|x| x.max(0.0));
    let sum: f32 = w.iter().sum();
    if sum <= 0.0 {
        [1.0, 0.0, 0.0]
    } else {
        w.map(|x| x / sum)
    }
}

/// The α/β/γ triangle: a point inside a triangle whose corners are α (default direction, top),
/// β (environment, bottom left) and γ (tropism, bottom right). Dragging keeps α + β + γ = 1.
pub fn weights_triangle_ui(ui: &mut Ui, weights: &mut [f32; 3]) -> Response {
    let size = Vec2::new(150.0, 130.0);
    let (rect, mut response) = ui.allocate_exact_size(size, Sense::drag());
    let corners = [
        Pos2::new(rect.center().x, rect.top() + 10.0),
        Pos2::new(rect.left() + 10.0, rect.bottom() - 10.0),
        Pos2::new(rect.right() - 10.0, rect.bottom() - 10.0),
    ];
    if let Some(pointer) = response.interact_pointer_pos()
        && (response.dragged() || response.drag_started())
    {
        let new = barycentric_clamped(pointer, corners);
        if new != *weights {
            *weights = new;
            response.mark_changed();
        }
    }
    let painter = ui.painter_at(rect);
    let stroke = Stroke::new(1.5, ui.visuals().text_color());
    painter.add(egui::Shape::convex_polygon(
        corners.to_vec(),
        ui.visuals().extreme_bg_color,
        stroke,
    ));
    let point = corners[0].to_vec2() * weights[0]
        + corners[1].to_vec2() * weights[1]
        + corners[2].to_vec2() * weights[2];
    painter.circle_filled(point.to_pos2(), 6.0, Color32::from_rgb(80, 180, 60));
    for (corner, name) in corners.iter().zip(["α", "β", "γ"]) {
        painter.text(
            *corner,
            egui::Align2::CENTER_CENTER,
            name,
            egui::FontId::proportional(12.0),
            ui.visuals().strong_text_color(),
        );
    }
    let label = format!(
        "α β γ triangle: α {:.2} β {:.2} γ {:.2}",
        weights[0], weights[1], weights[2]
    );
    response.widget_info(|| WidgetInfo::labeled(egui::Role::Canvas, true, "α β γ triangle"));
    response.on_hover_text(label)
}

/// The tropism arrow: drag its tip around the dial to set θ (angle from vertical).
pub fn tropism_arrow_ui(ui: &mut Ui, theta: &mut f32) -> Response {
    let (rect, mut response) = ui.allocate_exact_size(Vec2::splat(90.0), Sense::drag());
    let centre = rect.center();
    if let Some(pointer) = response.interact_pointer_pos()
        && response.dragged()
    {
        let d = pointer - centre;
        if d.length() > 4.0 {
            *theta = d.x.atan2(-d.y);
            response.mark_changed();
        }
    }
    let painter = ui.painter_at(rect);
    painter.circle_stroke(
        centre,
        40.0,
        Stroke::new(1.0, ui.visuals().weak_text_color()),
    );
    let tip = centre + 36.0 * Vec2::new(theta.sin(), -theta.cos());
    painter.arrow(
        centre,
        tip - centre,
        Stroke::new(2.5, Color32::from_rgb(230, 160, 40)),
    );
    response.widget_info(|| WidgetInfo::labeled(egui::Role::Canvas, true, "tropism θ"));
    response
}

/// The gravimorphism ellipse: drag to set its semi-axes, pinch to scale it.
pub fn gravimorphism_ellipse_ui(ui: &mut Ui, axes: &mut [f32; 2]) -> Response {
    let (rect, mut response) = ui.allocate_exact_size(Vec2::new(120.0, 90.0), Sense::drag());
    let centre = rect.center();
    if response.dragged() {
        let d = response.drag_delta();
        axes[0] = (axes[0] + d.x / 40.0).clamp(0.1, 2.0);
        axes[1] = (axes[1] - d.y / 40.0).clamp(0.1, 2.0);
        response.mark_changed();
    }
    if response.hovered() {
        let zoom = ui.input(|i| i.zoom_delta());
        if (zoom - 1.0).abs() > 1e-3 {
            *axes = axes.map(|a| (a * zoom).clamp(0.1, 2.0));
            response.mark_changed();
        }
    }
    let painter = ui.painter_at(rect);
    let points: Vec<Pos2> = (0..48)
        .map(|i| {
            let t = i as f32 / 48.0 * std::f32::consts::TAU;
            centre + Vec2::new(axes[0] * 25.0 * t.cos(), -axes[1] * 25.0 * t.sin())
        })
        .collect();
    painter.add(egui::Shape::closed_line(
        points,
        Stroke::new(2.0, Color32::from_rgb(90, 150, 230)),
    ));
    response.widget_info(|| WidgetInfo::labeled(egui::Role::Canvas, true, "gravimorphism ellipse"));
    response
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn barycentric_weights_sum_to_one_even_outside_the_triangle() {
        let tri = [
            Pos2::new(0.0, 0.0),
            Pos2::new(10.0, 0.0),
            Pos2::new(0.0, 10.0),
        ];
        for p in [
            Pos2::new(2.0, 3.0),
            Pos2::new(-5.0, 20.0),
            Pos2::new(100.0, -3.0),
        ] {
            let w = barycentric_clamped(p, tri);
            assert!((w.iter().sum::<f32>() - 1.0).abs() < 1e-5, "{w:?}");
            assert!(w.iter().all(|x| *x >= 0.0));
        }
        let w = barycentric_clamped(Pos2::new(10.0, 0.0), tri);
        assert!((w[1] - 1.0).abs() < 1e-5);
    }
}
