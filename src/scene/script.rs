//! Moving a scene through time with events at given steps: the one way stills, animations and
//! replays run a scene, so all three agree with the player about what step N shows.

use super::{Event, Scene};

/// Events at steps (in step order), applied to a scene as it advances.
///
/// An event at step S lands after S steps have run and before step S+1, as in the player:
/// running to S applies the events at S. Calm stretches between events go to
/// [`Scene::advance`] in one piece (for the pool, many times faster than single steps).
#[derive(Clone, Debug)]
pub struct Script<'a> {
    events: &'a [(u64, Event)],
    next: usize,
    step: u64,
}

impl<'a> Script<'a> {
    /// A script at step 0; `events` must be sorted by step (a replay's are).
    pub fn new(events: &'a [(u64, Event)]) -> Script<'a> {
        debug_assert!(events.windows(2).all(|w| w[0].0 <= w[1].0), "events are in step order");
        Script { events, next: 0, step: 0 }
    }

    /// Steps run so far.
    pub fn step(&self) -> u64 {
        self.step
    }

    /// Runs `scene` to `target` steps (no further back than where it is), applying every
    /// event up to and including those at `target`.
    pub fn run_to(&mut self, scene: &mut dyn Scene, target: u64) {
        self.run(scene, target, false);
    }

    /// Like [`Script::run_to`], but at `target` stops before the first screenshot event: the
    /// state that screenshot shows (events recorded after it at the same step are left out).
    pub fn run_to_screenshot(&mut self, scene: &mut dyn Scene, target: u64) {
        self.run(scene, target, true);
    }

    fn run(&mut self, scene: &mut dyn Scene, target: u64, stop_at_screenshot: bool) {
        while let Some((at, event)) = self.events.get(self.next) {
            if *at > target {
                break;
            }
            if *at > self.step {
                scene.advance(at - self.step);
                self.step = *at;
            }
            if stop_at_screenshot && *at == target && matches!(event, Event::Screenshot(_)) {
                return;
            }
            scene.apply(event);
            self.next += 1;
        }
        if target > self.step {
            scene.advance(target - self.step);
            self.step = target;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::pool::{PoolScene, PoolSettings};
    use crate::sim::ripple::Stone;

    fn pool() -> PoolScene {
        PoolScene::new(40, 30, PoolSettings { rain_rate: 0.2, ..PoolSettings::default() }).unwrap()
    }

    #[test]
    fn events_land_at_their_steps_like_single_steps() {
        let stone = |x| Event::Stone(Stone::new(x, 10, 3, 90).unwrap());
        let events = vec![(0, stone(5)), (7, stone(20)), (7, Event::Screenshot("s.png".into())), (7, stone(30))];
        let mut scripted = pool();
        let mut script = Script::new(&events);
        script.run_to(&mut scripted, 4);
        script.run_to(&mut scripted, 12);
        let mut by_hand = pool();
        by_hand.apply(&events[0].1);
        by_hand.advance(7);
        by_hand.apply(&events[1].1);
        by_hand.apply(&events[3].1);
        by_hand.advance(5);
        assert_eq!(scripted.pool().heights(), by_hand.pool().heights());
        assert_eq!(script.step(), 12);

        let mut shot = pool();
        Script::new(&events).run_to_screenshot(&mut shot, 7);
        let mut before = pool();
        before.apply(&events[0].1);
        before.advance(7);
        before.apply(&events[1].1);
        assert_eq!(shot.pool().heights(), before.pool().heights(), "the stone after the screenshot is left out");
    }
}
