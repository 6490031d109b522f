//! A small ratatui app that embeds a tidepool scene: the pool in a bordered block beside a
//! text panel. `space` drops a stone at a random spot, a click drops one where you click,
//! `q` quits.
//!
//!     cargo run --release --example ratatui_pool --features ratatui

use std::time::{Duration, Instant};

use ratatui::crossterm::event::{self, Event, KeyCode, KeyEventKind, MouseButton, MouseEventKind};
use ratatui::layout::{Constraint, Layout, Rect};
use ratatui::widgets::{Block, Paragraph, Wrap};
use tidepool::widget::{SceneWidget, SceneWidgetState};
use tidepool::{PoolScene, PoolSettings, Scene, Stone};

/// The pool steps 60 times a second, as in the player; frames are drawn 30 times a second.
const STEP: Duration = Duration::from_micros(16_667);
const FRAME: Duration = Duration::from_millis(33);

fn main() -> std::io::Result<()> {
    let mut terminal = ratatui::init();
    ratatui::crossterm::execute!(std::io::stdout(), ratatui::crossterm::event::EnableMouseCapture)?;
    let result = run(&mut terminal);
    let _ = ratatui::crossterm::execute!(std::io::stdout(), ratatui::crossterm::event::DisableMouseCapture);
    ratatui::restore();
    result
}

/// The pool's area and the panel's, inside the borders.
fn areas(screen: Rect) -> (Rect, Rect) {
    let [left, right] = Layout::horizontal([Constraint::Percentage(65), Constraint::Percentage(35)]).areas(screen);
    (Block::bordered().inner(left), right)
}

fn run(terminal: &mut ratatui::DefaultTerminal) -> std::io::Result<()> {
    let settings = PoolSettings { rain_rate: 0.02, ..PoolSettings::default() };
    let (pool_area, _) = areas(terminal.get_frame().area());
    let (w, h) = SceneWidget::picture_size(pool_area);
    let mut pool = PoolScene::new(w, h, settings).expect("a terminal-sized pool");
    let mut state = SceneWidgetState::default();
    let (mut stones, mut seed) = (0u32, 0x2545_f491_u32);
    let mut next_step = Instant::now();
    loop {
        let now = Instant::now();
        while next_step <= now {
            pool.advance(1);
            next_step += STEP;
        }
        terminal.draw(|frame| {
            let (pool_area, panel) = areas(frame.area());
            let left = Block::bordered().title(" tidepool ");
            frame.render_widget(left, Rect { x: pool_area.x - 1, y: pool_area.y - 1, width: pool_area.width + 2, height: pool_area.height + 2 });
            frame.render_stateful_widget(SceneWidget::new(&mut pool), pool_area, &mut state);
            let text = format!(
                "A tidepool scene inside a ratatui app.\n\nspace  a stone at random\nclick  a stone there\nq      quit\n\nstones dropped: {stones}\npool: {}x{} pixels",
                pool.width(),
                pool.height()
            );
            frame.render_widget(Paragraph::new(text).wrap(Wrap { trim: false }).block(Block::bordered().title(" panel ")), panel);
        })?;
        if !event::poll(FRAME)? {
            continue;
        }
        match event::read()? {
            Event::Key(key) if key.kind == KeyEventKind::Press => match key.code {
                KeyCode::Char('q') | KeyCode::Esc => return Ok(()),
                KeyCode::Char(' ') => {
                    // A small xorshift: the example needs no random-number crate.
                    seed ^= seed << 13;
                    seed ^= seed >> 17;
                    seed ^= seed << 5;
                    let (x, y) = (seed % pool.width(), (seed / 7919) % pool.height());
                    pool.drop_stone(Stone::clamped(x as i32, y as i32, 3, 96));
                    stones += 1;
                }
                _ => {}
            },
            Event::Mouse(m) if m.kind == MouseEventKind::Down(MouseButton::Left) => {
                let (area, _) = areas(terminal.get_frame().area());
                if area.contains((m.column, m.row).into()) {
                    let (x, y) = (m.column - area.x, 2 * (m.row - area.y));
                    pool.drop_stone(Stone::clamped(i32::from(x), i32::from(y), 3, 96));
                    stones += 1;
                }
            }
            Event::Resize(..) => {
                let (area, _) = areas(terminal.get_frame().area());
                let (w, h) = SceneWidget::picture_size(area);
                let _ = Scene::resize(&mut pool, w, h);
            }
            _ => {}
        }
    }
}
