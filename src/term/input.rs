//! Terminal events -> the player's inputs, with motion coalesced.
//!
//! Only key presses count (some platforms also report releases). The mouse is reported for
//! button presses and drags only (mode 1002, see [`crate::term::guard::ENTER`]), not for every
//! motion, so a moving mouse sends nothing; a drag still produces an event per cell crossed,
//! which [`coalesce`] reduces to the latest position per batch (the stir interpolates the
//! path), as it does for bursts of resize events.
//!
//! A click means the upper pixel of the clicked cell. SGR-pixels reporting (mode 1016) is not
//! turned on: crossterm reports its pixel coordinates as if they were cells, nothing tells the
//! two apart without a mode query crossterm cannot parse, and tmux does not pass it through; a
//! half-cell of precision is not worth a click landing in the wrong place.

use crossterm::event::{Event, KeyCode, KeyEvent, KeyEventKind, KeyModifiers, MouseButton, MouseEvent, MouseEventKind};

/// What the user asked for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Input {
    /// Leave (`q`, `Esc`, `Ctrl-C`).
    Quit,
    /// `Esc`: closes the help if it is open, else quits.
    Escape,
    /// A stone at a random spot (`space`).
    RandomStone,
    /// Move the aim by (columns, rows) (arrow keys, `hjkl`).
    Aim(i32, i32),
    /// A stone at the aim (`enter`).
    DropAtAim,
    /// `r`.
    ToggleRain,
    /// `c`.
    Clear,
    /// `+` (true) or `-` (false).
    StoneSize(bool),
    /// `[` (true: damp more) or `]`.
    Damping(bool),
    /// `p`.
    Pause,
    /// `s`.
    Screenshot,
    /// `Tab`.
    NextScene,
    /// `?`.
    Help,
    /// Any other character, for the scene's own keys.
    Other(char),
    /// A mouse button went down in cell (column, row); `big` for the right button.
    Press {
        /// Column.
        col: u16,
        /// Row.
        row: u16,
        /// Right button.
        big: bool,
    },
    /// The left button was dragged to cell (column, row).
    Drag {
        /// Column.
        col: u16,
        /// Row.
        row: u16,
    },
    /// The mouse button was released.
    Release,
    /// The terminal is now (columns, rows).
    Resize(u16, u16),
}

/// The input a terminal event means, if any.
pub fn map_event(event: Event) -> Option<Input> {
    match event {
        Event::Key(key) => map_key(key),
        Event::Mouse(mouse) => map_mouse(mouse),
        Event::Resize(cols, rows) => Some(Input::Resize(cols, rows)),
        _ => None,
    }
}

fn map_key(key: KeyEvent) -> Option<Input> {
    if key.kind != KeyEventKind::Press {
        return None;
    }
    if key.modifiers.contains(KeyModifiers::CONTROL) {
        return matches!(key.code, KeyCode::Char('c' | 'C')).then_some(Input::Quit);
    }
    Some(match key.code {
        KeyCode::Esc => Input::Escape,
        KeyCode::Enter => Input::DropAtAim,
        KeyCode::Tab | KeyCode::BackTab => Input::NextScene,
        KeyCode::Left => Input::Aim(-1, 0),
        KeyCode::Right => Input::Aim(1, 0),
        KeyCode::Up => Input::Aim(0, -1),
        KeyCode::Down => Input::Aim(0, 1),
        KeyCode::Char(c) => match c {
            'q' | 'Q' => Input::Quit,
            ' ' => Input::RandomStone,
            'h' => Input::Aim(-1, 0),
            'l' => Input::Aim(1, 0),
            'k' => Input::Aim(0, -1),
            'j' => Input::Aim(0, 1),
            'r' => Input::ToggleRain,
            'c' => Input::Clear,
            '+' | '=' => Input::StoneSize(true),
            '-' | '_' => Input::StoneSize(false),
            '[' => Input::Damping(true),
            ']' => Input::Damping(false),
            'p' => Input::Pause,
            's' => Input::Screenshot,
            '?' => Input::Help,
            other => Input::Other(other),
        },
        _ => return None,
    })
}

fn map_mouse(mouse: MouseEvent) -> Option<Input> {
    let (col, row) = (mouse.column, mouse.row);
    match mouse.kind {
        MouseEventKind::Down(MouseButton::Left) => Some(Input::Press { col, row, big: false }),
        MouseEventKind::Down(MouseButton::Right) => Some(Input::Press { col, row, big: true }),
        MouseEventKind::Drag(MouseButton::Left) => Some(Input::Drag { col, row }),
        MouseEventKind::Up(_) => Some(Input::Release),
        _ => None,
    }
}

/// Merges runs of drags (and of resizes) into their last event; everything else is kept in
/// order.
pub fn coalesce(inputs: impl IntoIterator<Item = Input>) -> Vec<Input> {
    let mut out: Vec<Input> = Vec::new();
    for input in inputs {
        match (out.last_mut(), input) {
            (Some(last @ Input::Drag { .. }), Input::Drag { .. })
            | (Some(last @ Input::Resize(..)), Input::Resize(..)) => *last = input,
            _ => out.push(input),
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crossterm::event::KeyEventState;

    fn key(code: KeyCode, modifiers: KeyModifiers) -> Event {
        Event::Key(KeyEvent { code, modifiers, kind: KeyEventKind::Press, state: KeyEventState::NONE })
    }

    #[test]
    fn keys() {
        let k = |c| map_event(key(KeyCode::Char(c), KeyModifiers::NONE));
        assert_eq!(k('q'), Some(Input::Quit));
        assert_eq!(k(' '), Some(Input::RandomStone));
        assert_eq!(k('j'), Some(Input::Aim(0, 1)));
        assert_eq!(k('['), Some(Input::Damping(true)));
        assert_eq!(k('w'), Some(Input::Other('w')));
        assert_eq!(map_event(key(KeyCode::Char('c'), KeyModifiers::CONTROL)), Some(Input::Quit));
        assert_eq!(map_event(key(KeyCode::Char('x'), KeyModifiers::CONTROL)), None);
        assert_eq!(map_event(key(KeyCode::Esc, KeyModifiers::NONE)), Some(Input::Escape));
        assert_eq!(map_event(key(KeyCode::Left, KeyModifiers::NONE)), Some(Input::Aim(-1, 0)));
        let release = KeyEvent {
            code: KeyCode::Char('q'),
            modifiers: KeyModifiers::NONE,
            kind: KeyEventKind::Release,
            state: KeyEventState::NONE,
        };
        assert_eq!(map_event(Event::Key(release)), None);
    }

    #[test]
    fn mouse() {
        let m = |kind| map_event(Event::Mouse(MouseEvent { kind, column: 3, row: 4, modifiers: KeyModifiers::NONE }));
        assert_eq!(m(MouseEventKind::Down(MouseButton::Left)), Some(Input::Press { col: 3, row: 4, big: false }));
        assert_eq!(m(MouseEventKind::Down(MouseButton::Right)), Some(Input::Press { col: 3, row: 4, big: true }));
        assert_eq!(m(MouseEventKind::Drag(MouseButton::Left)), Some(Input::Drag { col: 3, row: 4 }));
        assert_eq!(m(MouseEventKind::Moved), None);
    }

    #[test]
    fn drags_and_resizes_coalesce() {
        let drag = |col| Input::Drag { col, row: 1 };
        let inputs = [drag(1), drag(2), drag(3), Input::Clear, drag(4), Input::Resize(5, 5), Input::Resize(9, 9)];
        assert_eq!(coalesce(inputs), vec![drag(3), Input::Clear, drag(4), Input::Resize(9, 9)]);
        // A flood of drags is one input.
        assert_eq!(coalesce((0..10_000).map(|i| drag(i as u16))).len(), 1);
    }
}
