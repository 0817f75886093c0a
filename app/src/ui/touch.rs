//! Touches on the AR view: real touches and the mouse (as touch id 0) become
//! [`InputEvent::Touch`] in camera-image pixels.

use egui::{Pos2, Ui};

use crate::render::Intrinsics;
use crate::render::resources::letterbox;
use crate::state::{InputEvent, TouchPhase};

/// Converts a window position (points) into camera-image pixels.
pub fn image_from_window(
    pos: Pos2,
    pixels_per_point: f32,
    target: (u32, u32),
    k: &Intrinsics,
) -> glam::Vec2 {
    let region = letterbox(target, k);
    let px = glam::Vec2::new(pos.x * pixels_per_point, pos.y * pixels_per_point);
    glam::Vec2::new(
        (px.x - region[0]) / region[2] * k.width as f32,
        (px.y - region[1]) / region[3] * k.height as f32,
    )
}

/// Where camera-image pixel `pixel` is drawn in the window, points (the inverse of
/// [`image_from_window`]).
pub fn window_from_image(
    pixel: glam::Vec2,
    pixels_per_point: f32,
    target: (u32, u32),
    k: &Intrinsics,
) -> Pos2 {
    let region = letterbox(target, k);
    let px = glam::Vec2::new(
        region[0] + pixel.x / k.width as f32 * region[2],
        region[1] + pixel.y / k.height as f32 * region[3],
    );
    Pos2::new(px.x / pixels_per_point, px.y / pixels_per_point)
}

/// Emits touch events for pointer and touch input inside `view` (not over the panels).
pub fn view_touches_ui(
    ui: &mut Ui,
    view: egui::Rect,
    target: (u32, u32),
    k: &Intrinsics,
    events: &mut Vec<InputEvent>,
) {
    let response = ui.interact(
        view,
        ui.scope_id().with("ar view"),
        egui::Sense::click_and_drag(),
    );
    let ppp = ui.ctx().pixels_per_point();
    let to_event = |phase, id, pos: Pos2| {
        let p = image_from_window(pos, ppp, target, k);
        InputEvent::Touch {
            phase,
            id,
            x: p.x,
            y: p.y,
        }
    };
    let mut had_touch = false;
    ui.input(|input| {
        for e in &input.events {
            if let egui::Event::Touch { id, phase, pos, .. } = e {
                had_touch = true;
                let phase = match phase {
                    egui::TouchPhase::Start if view.contains(*pos) => TouchPhase::Start,
                    egui::TouchPhase::Start => continue,
                    egui::TouchPhase::Move => TouchPhase::Move,
                    egui::TouchPhase::End | egui::TouchPhase::Cancel => TouchPhase::End,
                };
                events.push(to_event(phase, id.0 + 1, *pos));
            }
        }
    });
    if had_touch {
        return;
    }
    let Some(pos) = ui.input(|i| i.pointer.interact_pos()) else {
        return;
    };
    if response.is_pointer_button_down_on() && ui.input(|i| i.pointer.primary_pressed()) {
        events.push(to_event(TouchPhase::Start, 0, pos));
    } else if response.is_pointer_button_down_on()
        && ui.input(|i| i.pointer.delta() != egui::Vec2::ZERO)
    {
        events.push(to_event(TouchPhase::Move, 0, pos));
    } else if ui.input(|i| i.pointer.primary_released())
        && (response.drag_stopped() || response.clicked())
    {
        events.push(to_event(TouchPhase::End, 0, pos));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn window_from_image_undoes_image_from_window_in_a_letterboxed_portrait_window() {
        let k = Intrinsics::from_fov(640, 480, 1.0);
        let target = (1080, 2340);
        for pixel in [
            glam::Vec2::new(0.0, 0.0),
            glam::Vec2::new(320.0, 240.0),
            glam::Vec2::new(600.0, 17.0),
        ] {
            let pos = window_from_image(pixel, 3.0, target, &k);
            let back = image_from_window(pos, 3.0, target, &k);
            assert!(back.distance(pixel) < 1e-3, "{pixel} -> {pos:?} -> {back}");
        }
    }
}
