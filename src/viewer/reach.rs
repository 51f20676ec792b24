//! Which of the side panel's controls a user can reach: in view, by scrolling the panel, or not
//! at all (cut off at the bottom of a short window, or past the panel's right edge, which does
//! not scroll). The panel records where egui laid out each control this frame; the viewer's
//! screenshot prints the verdict, which `tests/viewer.rs` checks at 1280×720.

use egui::{Rect, Response};
use std::fmt;

/// Half a point: egui rounds rectangles to pixels.
const SLACK: f32 = 0.5;

/// How a control can be reached.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reachable {
    /// Wholly inside the visible part of the panel now.
    InView,
    /// Wholly visible at some offset of the panel's vertical scroll.
    ByScrolling,
    /// Never wholly visible: wider than the panel, taller than the view, or beyond the content.
    OutOfReach,
}

/// Where the panel's controls were laid out in one frame, against the panel's scroll view.
#[derive(Clone, Debug)]
pub struct Reach {
    /// The visible part of the scroll area (screen points, scroll bar excluded).
    pub view: Rect,
    /// Height of all that is in the scroll area, points.
    pub content_height: f32,
    /// How far the panel is scrolled down, points.
    pub offset: f32,
    /// Each control by name (its label) and its rectangle on the screen this frame.
    pub controls: Vec<(&'static str, Rect)>,
}

/// Nothing laid out yet: an empty view, in which nothing can be reached.
impl Default for Reach {
    fn default() -> Reach {
        Reach {
            view: Rect::ZERO,
            content_height: 0.0,
            offset: 0.0,
            controls: Vec::new(),
        }
    }
}

impl Reach {
    /// Note where `control` was laid out; returns it for chaining.
    pub fn place(&mut self, name: &'static str, control: Response) -> Response {
        self.controls.push((name, control.rect));
        control
    }

    /// How the control laid out at `rect` can be reached. The panel scrolls vertically only,
    /// between offset 0 and `content_height - view height`.
    pub fn of(&self, rect: Rect) -> Reachable {
        let v = self.view;
        let fits_across = rect.left() >= v.left() - SLACK && rect.right() <= v.right() + SLACK;
        if !fits_across || rect.height() > v.height() + SLACK {
            return Reachable::OutOfReach;
        }
        if rect.top() >= v.top() - SLACK && rect.bottom() <= v.bottom() + SLACK {
            return Reachable::InView;
        }
        // Offsets that show the control: those in [top + h - view h, top] in content coordinates.
        let top = rect.top() - (v.top() - self.offset);
        let max_offset = (self.content_height - v.height()).max(0.0);
        if top >= -SLACK && top + rect.height() - v.height() <= max_offset + SLACK {
            Reachable::ByScrolling
        } else {
            Reachable::OutOfReach
        }
    }

    /// The names of the controls reached the way `how` says, in panel order.
    pub fn named(&self, how: Reachable) -> Vec<&'static str> {
        let of = |&&(_, r): &&(&str, Rect)| self.of(r) == how;
        self.controls.iter().filter(of).map(|&(n, _)| n).collect()
    }
}

/// One line: the controls in view, by scrolling and out of reach, by name.
impl fmt::Display for Reach {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let list = |how| {
            let names = self.named(how);
            if names.is_empty() {
                "none".to_string()
            } else {
                names.join(", ")
            }
        };
        write!(
            f,
            "panel ({:.0} of {:.0} points in view): in view: {}; by scrolling: {}; out of reach: {}",
            self.view.height(),
            self.content_height,
            list(Reachable::InView),
            list(Reachable::ByScrolling),
            list(Reachable::OutOfReach)
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use egui::{pos2, vec2};

    fn reach(offset: f32) -> Reach {
        Reach {
            view: Rect::from_min_size(pos2(950.0, 0.0), vec2(320.0, 720.0)),
            content_height: 1000.0,
            offset,
            controls: vec![],
        }
    }

    fn at(x: f32, y: f32, w: f32, h: f32) -> Rect {
        Rect::from_min_size(pos2(x, y), vec2(w, h))
    }

    #[test]
    fn a_control_is_in_view_below_the_fold_or_out_of_reach() {
        let r = reach(0.0);
        assert_eq!(r.of(at(960.0, 700.0, 100.0, 20.0)), Reachable::InView);
        // 280 points of content below the view: a control down to 1000 can be scrolled to.
        assert_eq!(r.of(at(960.0, 710.0, 100.0, 20.0)), Reachable::ByScrolling);
        assert_eq!(r.of(at(960.0, 980.0, 100.0, 20.0)), Reachable::ByScrolling);
        assert_eq!(r.of(at(960.0, 990.0, 100.0, 20.0)), Reachable::OutOfReach);
        // The panel does not scroll sideways.
        assert_eq!(r.of(at(1200.0, 10.0, 100.0, 20.0)), Reachable::OutOfReach);
        assert_eq!(r.of(at(960.0, 10.0, 100.0, 800.0)), Reachable::OutOfReach);
    }

    #[test]
    fn scrolled_down_the_controls_above_are_reached_by_scrolling_back() {
        // Scrolled by 280: the content's top is at -280 on the screen.
        let r = reach(280.0);
        assert_eq!(r.of(at(960.0, -280.0, 100.0, 20.0)), Reachable::ByScrolling);
        assert_eq!(r.of(at(960.0, -290.0, 100.0, 20.0)), Reachable::OutOfReach);
        assert_eq!(r.of(at(960.0, 700.0, 100.0, 20.0)), Reachable::InView);
        assert_eq!(r.of(at(960.0, 715.0, 100.0, 20.0)), Reachable::OutOfReach);
    }
}
