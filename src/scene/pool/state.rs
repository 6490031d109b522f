//! The pool's state as bytes, and back: what a machine that joins a shared pool late needs to
//! carry on from where the others are (`tidepool serve --bus`: a snapshot plus the events
//! after it). Only the state that the future depends on is kept: both water states, the step
//! count, the rain's and the wind's random sources where they stand, the gusts' live packets
//! and the levels the `r` and `b` keys switch back to. The floor, the look and the sizes come
//! from the settings, which every machine of a pool shares; a snapshot of another pool's size
//! or grid is refused.
//!
//! The format is little-endian and versioned; every count read is checked against the scene
//! before anything is allocated, and nothing changes unless the whole snapshot reads.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use super::{PoolScene, Wind};
use crate::error::{Result, ValueError};
use crate::sim::breeze::gusts::{MAX_PACKETS, Packet};
use crate::sim::ripple::Damping;

/// The first bytes of a pool snapshot, then its version.
const MAGIC: &[u8; 4] = b"TPST";
const VERSION: u8 = 1;
/// The longest damping text (`Damping`'s display form) a snapshot holds.
const MAX_DAMPING_TEXT: usize = 32;

fn bad(why: impl Into<String>) -> crate::error::Error {
    ValueError::new("snapshot", why.into()).into()
}

impl PoolScene {
    /// The simulation's state now, as bytes (about four bytes a simulation cell).
    pub fn save_state(&self) -> Vec<u8> {
        let cells = self.pool.heights().len();
        let mut out = Vec::with_capacity(64 + 4 * cells + 40 * MAX_PACKETS);
        out.extend_from_slice(MAGIC);
        out.push(VERSION);
        for v in [self.pool.width() as u32, self.pool.height() as u32, self.grid] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        let damping = self.pool.damping().to_string();
        out.push(damping.len() as u8);
        out.extend_from_slice(damping.as_bytes());
        out.extend_from_slice(&self.pool.steps().to_le_bytes());
        for v in self.pool.heights().iter().chain(self.pool.previous_heights()) {
            out.extend_from_slice(&v.to_le_bytes());
        }
        for v in [self.rain.rate(), self.rain_when_on, self.breeze_when_on] {
            out.extend_from_slice(&v.to_le_bytes());
        }
        put_rng(&mut out, &self.rain.rng);
        match &self.wind {
            Wind::Wavelets(b) => {
                out.push(0);
                out.extend_from_slice(&b.level().to_le_bytes());
                put_rng(&mut out, &b.rng);
            }
            Wind::Gusts(g) => {
                out.push(1);
                out.extend_from_slice(&g.level().to_le_bytes());
                put_rng(&mut out, &g.rng);
                out.extend_from_slice(&g.step.to_le_bytes());
                out.push(u8::from(g.primed));
                out.extend_from_slice(&(g.packets.len() as u32).to_le_bytes());
                for p in &g.packets {
                    let floats = [p.origin.0, p.origin.1, p.direction.0, p.direction.1];
                    for v in floats.into_iter().chain([p.wavenumber, p.radius, p.amplitude, p.phase]) {
                        out.extend_from_slice(&v.to_le_bytes());
                    }
                    out.extend_from_slice(&p.born.to_le_bytes());
                }
            }
        }
        out
    }

    /// Carries on from `bytes` (made by [`PoolScene::save_state`] of a pool of the same size,
    /// grid and wind style): the same steps and events after it give the same water bit for
    /// bit. On an error nothing changes.
    pub fn restore_state(&mut self, bytes: &[u8]) -> Result<()> {
        let mut r = Reader(bytes);
        if r.take(4)? != MAGIC || r.u8()? != VERSION {
            return Err(bad("not a pool snapshot of this version"));
        }
        let (cols, rows, grid) = (r.u32()?, r.u32()?, r.u32()?);
        if (cols as usize, rows as usize, grid) != (self.pool.width(), self.pool.height(), self.grid) {
            return Err(bad(format!(
                "the snapshot is of a {cols}x{rows}-cell pool on grid {grid}, this one is {}x{} on grid {}",
                self.pool.width(),
                self.pool.height(),
                self.grid
            )));
        }
        let damping_len = r.u8()? as usize;
        if damping_len > MAX_DAMPING_TEXT {
            return Err(bad("damping text too long"));
        }
        let damping: Damping = std::str::from_utf8(r.take(damping_len)?)
            .ok()
            .and_then(|t| t.parse().ok())
            .ok_or_else(|| bad("bad damping"))?;
        let steps = r.u64()?;
        let cells = self.pool.heights().len();
        let mut heights = Vec::with_capacity(2 * cells);
        for _ in 0..2 * cells {
            heights.push(i16::from_le_bytes(r.array()?));
        }
        let (rain_rate, rain_when_on, breeze_when_on) = (r.f64()?, r.f64()?, r.f64()?);
        let rain_rng = r.rng()?;
        let wind = match (r.u8()?, &self.wind) {
            (0, Wind::Wavelets(b)) => {
                let mut b = b.clone();
                b.set_level(r.f64()?);
                b.rng = r.rng()?;
                Wind::Wavelets(b)
            }
            (1, Wind::Gusts(g)) => {
                let mut g = g.clone();
                g.set_level(r.f64()?);
                g.rng = r.rng()?;
                g.step = r.u64()? as i64;
                g.primed = r.u8()? != 0;
                let count = r.u32()? as usize;
                if count > MAX_PACKETS {
                    return Err(bad(format!("{count} gust packets, at most {MAX_PACKETS}")));
                }
                g.packets.clear();
                for _ in 0..count {
                    let mut f = [0f32; 8];
                    for v in &mut f {
                        *v = f32::from_le_bytes(r.array()?);
                    }
                    let born = r.u64()? as i64;
                    g.packets.push(Packet {
                        origin: (f[0], f[1]),
                        direction: (f[2], f[3]),
                        wavenumber: f[4],
                        radius: f[5],
                        amplitude: f[6],
                        phase: f[7],
                        born,
                    });
                }
                Wind::Gusts(g)
            }
            _ => return Err(bad("the snapshot's wind style differs from this pool's")),
        };
        if !r.0.is_empty() {
            return Err(bad(format!("{} bytes after the end", r.0.len())));
        }
        // Everything read: now change the scene.
        let (current, previous) = heights.split_at(cells);
        if !self.pool.restore(current, previous, steps) {
            return Err(bad("the water's size differs"));
        }
        self.pool.set_damping(damping);
        self.rain.set_rate(rain_rate);
        self.rain.rng = rain_rng;
        self.rain_when_on = rain_when_on;
        self.breeze_when_on = breeze_when_on;
        self.wind = wind;
        Ok(())
    }
}

/// A ChaCha generator where it stands: its seed, stream and position in the stream.
fn put_rng(out: &mut Vec<u8>, rng: &ChaCha8Rng) {
    out.extend_from_slice(&rng.get_seed());
    out.extend_from_slice(&rng.get_stream().to_le_bytes());
    out.extend_from_slice(&rng.get_word_pos().to_le_bytes());
}

/// Bytes read from the front, each read checked against what is left.
struct Reader<'a>(&'a [u8]);

impl<'a> Reader<'a> {
    fn take(&mut self, n: usize) -> Result<&'a [u8]> {
        if self.0.len() < n {
            return Err(bad("the snapshot ends early"));
        }
        let (head, rest) = self.0.split_at(n);
        self.0 = rest;
        Ok(head)
    }

    fn array<const N: usize>(&mut self) -> Result<[u8; N]> {
        let mut out = [0; N];
        out.copy_from_slice(self.take(N)?);
        Ok(out)
    }

    fn u8(&mut self) -> Result<u8> {
        Ok(self.take(1)?[0])
    }

    fn u32(&mut self) -> Result<u32> {
        Ok(u32::from_le_bytes(self.array()?))
    }

    fn u64(&mut self) -> Result<u64> {
        Ok(u64::from_le_bytes(self.array()?))
    }

    fn f64(&mut self) -> Result<f64> {
        let v = f64::from_le_bytes(self.array()?);
        if !v.is_finite() {
            return Err(bad("a level is not a number"));
        }
        Ok(v)
    }

    fn rng(&mut self) -> Result<ChaCha8Rng> {
        let seed: [u8; 32] = self.array()?;
        let stream = self.u64()?;
        let word_pos = u128::from_le_bytes(self.array()?);
        let mut rng = ChaCha8Rng::from_seed(seed);
        rng.set_stream(stream);
        rng.set_word_pos(word_pos);
        Ok(rng)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::pool::PoolSettings;
    use crate::scene::{Event, Scene};
    use crate::sim::breeze::BreezeStyle;
    use crate::sim::ripple::Stone;
    use tiny_skia::Pixmap;

    fn settings(style: BreezeStyle) -> PoolSettings {
        PoolSettings { rain_rate: 0.3, breeze: 1.0, breeze_style: style, seed: 7, ..PoolSettings::default() }
    }

    fn picture(scene: &mut PoolScene) -> Vec<u8> {
        let mut out = Pixmap::new(scene.width(), scene.height()).unwrap();
        PoolScene::render(scene, &mut out);
        out.data().to_vec()
    }

    /// A pool restored from a snapshot and the one it was taken of run on identically: the
    /// same steps and stones give the same pixels, for both wind styles.
    #[test]
    fn a_restored_pool_carries_on_bit_for_bit() {
        for style in [BreezeStyle::Wavelets, BreezeStyle::Gusts] {
            let mut a = PoolScene::new(64, 36, settings(style)).unwrap();
            a.apply(&Event::Stone(Stone::clamped(20, 10, 4, 128)));
            Scene::advance(&mut a, 137);
            let bytes = a.save_state();
            let mut b = PoolScene::new(64, 36, settings(style)).unwrap();
            b.restore_state(&bytes).unwrap();
            for scene in [&mut a, &mut b] {
                scene.apply(&Event::Stone(Stone::clamped(40, 20, 3, 128)));
                Scene::advance(scene, 211);
            }
            assert_eq!(picture(&mut a), picture(&mut b), "{style:?}");
            assert_eq!(a.save_state(), b.save_state(), "{style:?}");
        }
    }

    /// A fresh pool is not the pool after 137 steps: the test above would notice a restore
    /// that did nothing.
    #[test]
    fn a_fresh_pool_differs() {
        let mut a = PoolScene::new(64, 36, settings(BreezeStyle::Gusts)).unwrap();
        Scene::advance(&mut a, 137);
        let mut b = PoolScene::new(64, 36, settings(BreezeStyle::Gusts)).unwrap();
        assert_ne!(a.save_state(), b.save_state());
        assert_ne!(picture(&mut a), picture(&mut b));
    }

    /// Cut, padded, corrupted or foreign snapshots are refused with a reason, and the scene is
    /// left as it was.
    #[test]
    fn bad_snapshots_are_refused_and_change_nothing() {
        let mut a = PoolScene::new(32, 18, settings(BreezeStyle::Gusts)).unwrap();
        Scene::advance(&mut a, 50);
        let good = a.save_state();
        let mut b = PoolScene::new(32, 18, settings(BreezeStyle::Gusts)).unwrap();
        let before = b.save_state();
        let mut padded = good.clone();
        padded.push(0);
        let mut corrupt = good.clone();
        corrupt[0] = b'X';
        for bytes in [&good[..good.len() / 2], &padded[..], &corrupt[..], &[][..]] {
            assert!(b.restore_state(bytes).is_err());
            assert_eq!(b.save_state(), before);
        }
        let mut other = PoolScene::new(33, 18, settings(BreezeStyle::Gusts)).unwrap();
        assert!(other.restore_state(&good).unwrap_err().to_string().contains("33x18"));
        let mut wavelets = PoolScene::new(32, 18, settings(BreezeStyle::Wavelets)).unwrap();
        assert!(wavelets.restore_state(&good).unwrap_err().to_string().contains("wind style"));
    }
}
