//! What the firmware shows, one mode per build: the embedded scenes in turn (the default), an
//! orbit around each (`orbit`), or the ladder of levers on the first scene (`ladder`).

use crate::cores::TwoCores;
use crate::display::SetUp;
use crate::sleep::{sleep_ms, Alarm0, Timer};
#[cfg(any(feature = "ladder", not(feature = "orbit")))]
use board_records::FrameDone;
use board_records::{Channel, Record};
use display_interface::DisplayError;
use embedded_graphics_core::draw_target::DrawTarget;
use embedded_hal::digital::OutputPin;
#[cfg(not(any(feature = "ladder", feature = "slot")))]
use firmware::app::EMBEDDED;
use firmware::app::{render_embedded_at, AppError, Board, Embedded, Report, SceneMemory, ShareMemory, Shot, Shown};
#[cfg(not(any(feature = "ladder", feature = "slot")))]
use firmware::stack;
use lattice_rt::dither::Shade;
use lattice_rt::render::RenderError;

/// The pause between two scenes.
const PAUSE_MS: u32 = 3000;

/// How long the line that says why the last boot panicked stays on the panel.
const PANIC_LINE_MS: u32 = 800;

/// How often a panel that does not answer is set up again.
const RETRY_MS: u32 = 100;

/// How often the board asks the panel whether it answers while it waits between frames
/// ([`Panel::pause`]).
const PROBE_MS: u32 = 20;

/// How often the picture is sent again while it stands ([`SetUp::refresh`], in place of that
/// moment's probe): a power cut too short for any probe or transfer to see leaves the panel
/// dark for at most this long after the frame. 400 ms: a 128x64 refresh is about 1,100 bytes,
/// some 25 ms of a 400 kHz bus, so the bus still idles 94 % of the pause.
const REFRESH_MS: u32 = 400;

/// The records this board reports (`board_records`): `cargo xtask board` finds the channel by this
/// symbol in the emulated board's RAM and decodes them into the same types.
#[no_mangle]
static BOARD_RECORDS: Channel = Channel::new();

/// Reports `record` on [`BOARD_RECORDS`].
pub fn report(record: Record) {
    BOARD_RECORDS.send(&record);
}

/// How a pause between frames ended ([`Panel::pause`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Paused {
    /// Its time ran out: on to the next scene (the `slot` image: its scene again, as it was).
    Elapsed,
    /// The next-scene button was pressed (the `slot` image: its scene from its own camera).
    Next,
    /// The panel lost power and answers again: it shows nothing, so the frame is drawn again.
    Lost,
    /// The camera-turn button was pressed: the scene again, from a step further around it.
    Turn,
}

/// A frame's microseconds: the whole frame, and up to the first tile (its set-up).
type Micros = (u64, u64);

/// What a frame of scene `scene` reports (orbit mode reports whole orbits instead).
#[cfg(any(feature = "ladder", not(feature = "orbit")))]
fn frame_done(scene: usize, r: &Report, (us, setup_us): Micros) -> FrameDone {
    let s = &r.stats;
    FrameDone {
        scene: scene as u8,
        us,
        setup_us,
        share_us: r.share_us,
        rays: s.rays,
        object_tests: s.object_tests,
        cells: s.cells_visited,
        lattice_bytes: r.lattice_bytes as u32,
        stack: firmware::stack::high_water() as u32,
    }
}

/// The board as the modes use it: the display, the LED, the clock, both cores and the memory
/// of a frame.
pub struct Panel<'m, T, L> {
    /// The display, drawn tile by tile.
    pub target: T,
    /// Lit while a frame renders.
    pub led: L,
    /// The 1 MHz timer frames are timed with.
    pub timer: Timer,
    /// The alarm the firmware sleeps on between scenes.
    pub alarm: Alarm0,
    /// Core 1, which traces the second tile share of every frame.
    pub cores: TwoCores,
    /// Core 0's memory for a frame: the scene and its lattice when they are parsed and built at
    /// run time, and its scratch.
    pub st: &'m mut SceneMemory,
    /// Core 1's scratch and 1-bit frame.
    pub second: &'m mut ShareMemory,
}

impl<T: DrawTarget<Color = Shown, Error = DisplayError> + SetUp + Send, L: OutputPin> Panel<'_, T, L> {
    /// One frame, with the LED lit while it renders; its report and its microseconds, whole and
    /// up to the first tile (the set-up). The passes of
    /// a progressive frame (the `progressive` feature) follow each other without waiting for the
    /// bus: each reaches the panel as its bytes do, while the cores trace the next, and the LED
    /// goes out when the last is on the panel.
    pub fn show(&mut self, scene: Embedded, shot: &Shot) -> Result<(Report, Micros), AppError<'static, T::Error>> {
        crate::guard::feed();
        self.set_up_panel();
        let timer = self.timer;
        let t0 = timer.get_counter();
        #[cfg(feature = "gray")]
        let refresh0 = crate::display::gray::refresh_us();
        let _ = self.led.set_high();
        let now = || timer.get_counter().ticks();
        let board = Board {
            cores: &mut self.cores,
            second: self.second,
            now: &now,
            shown: &mut |_| {},
            alive: &crate::guard::alive,
        };
        let result = render_embedded_at(scene, self.st, &mut self.target, &mut crate::display::Pump, shot, board);
        // The frame is on the panel once the bus has sent its last queued byte.
        let sent = self.target.flush();
        let _ = self.led.set_low();
        #[cfg(feature = "gray")]
        defmt::info!(
            "the gray refresh took {} us of core 0 during the frame",
            crate::display::gray::refresh_us().wrapping_sub(refresh0)
        );
        let result = result.and_then(|r| {
            sent.map(|()| r).map_err(|_| AppError::Render(RenderError::Draw(DisplayError::BusWriteError)))
        });
        result.map(|r| {
            let setup_us = r.tiles_at.saturating_sub(t0.ticks());
            (r, ((timer.get_counter() - t0).to_micros(), setup_us))
        })
    }

    /// Reports why the last boot panicked: in the log, as a record, and on the panel for
    /// [`PANIC_LINE_MS`]. Out of line: its buffers (and the message's 1 KiB frame) take stack
    /// only when a boot has something to report.
    #[inline(never)]
    pub fn report_panic(&mut self, why: &str) {
        defmt::error!("the last boot panicked: {}", why);
        report(Record::Panicked);
        const HEAD: &str = "Panicked: ";
        // The note holds at most 120 bytes of whole characters: the line fits.
        let mut bytes = [0u8; 160];
        let n = (HEAD.len() + why.len()).min(bytes.len());
        for (b, c) in bytes.iter_mut().zip(HEAD.bytes().chain(why.bytes())) {
            *b = c;
        }
        let text = core::str::from_utf8(&bytes[..n]).unwrap_or(HEAD);
        if self.message(text).is_err() {
            defmt::error!("the display did not take the message");
        }
        // Long enough to read the line, short enough that a picture follows within a second.
        for _ in 0..PANIC_LINE_MS / PROBE_MS {
            sleep_ms(&mut self.alarm, PROBE_MS);
            crate::guard::feed();
        }
    }

    /// Shows `text` on the panel in place of a picture (`board_records::message`, as the host
    /// draws it), with the LED lit until it is on the panel, as for a frame.
    #[inline(never)]
    pub fn message(&mut self, text: &str) -> Result<(), DisplayError> {
        use embedded_graphics_core::geometry::{Point, Size};
        use embedded_graphics_core::primitives::Rectangle;
        use firmware::app::{HEIGHT, WIDTH};
        use lattice_rt::BitFrame;
        const BYTES: usize = BitFrame::bytes(WIDTH as u32, HEIGHT as u32);
        let (w, h) = (WIDTH as u32, HEIGHT as u32);
        self.set_up_panel();
        let _ = self.led.set_high();
        let mut bits = [0u8; BYTES];
        let Some(mut frame) = BitFrame::new(w, h, &mut bits) else { return Err(DisplayError::OutOfBoundsError) };
        let Ok(()) = board_records::message::draw(&mut frame, w, h, text);
        // Sent in bands of tiles, as a frame is (the display takes page-aligned bands).
        let band = u32::from(firmware::app::RENDERED.tile);
        for y0 in (0..h).step_by(band as usize) {
            let rows = band.min(h - y0);
            let colors = (y0..y0 + rows)
                .flat_map(|y| (0..w).map(move |x| (x, y)))
                .map(|(x, y)| Shown::from_step(u8::from(frame.get(x, y)) * Shown::STEPS));
            self.target.fill_contiguous(&Rectangle::new(Point::new(0, y0 as i32), Size::new(w, rows)), colors)?;
        }
        let sent = self.target.flush();
        let _ = self.led.set_low();
        sent.map_err(|_| DisplayError::BusWriteError)
    }

    /// Sets the panel up for the next frame ([`SetUp`]), again every [`RETRY_MS`] while it does
    /// not answer (a loose wire): logged when it stops and when it starts answering again.
    fn set_up_panel(&mut self) {
        if self.target.set_up().is_ok() {
            return;
        }
        defmt::warn!("the display does not answer: setting it up again every {} ms", RETRY_MS);
        while self.target.set_up().is_err() {
            sleep_ms(&mut self.alarm, RETRY_MS);
            crate::guard::feed();
        }
        defmt::info!("the display answers again");
    }

    /// Sleeps between scenes, asking the panel every [`PROBE_MS`] whether it answers and
    /// sending the picture again every [`REFRESH_MS`]: ends at once when it stopped answering
    /// and answers again ([`Paused::Lost`]), or when a button is pressed ([`crate::button`]).
    pub fn pause(&mut self) -> Paused {
        let mut lost = false;
        for probe in 1..=PAUSE_MS / PROBE_MS {
            sleep_ms(&mut self.alarm, PROBE_MS);
            crate::guard::feed();
            crate::guard::check_requests();
            if let Some(p) = button() {
                return p;
            }
            let refresh = !lost && probe % (REFRESH_MS / PROBE_MS) == 0;
            let answers = if refresh { self.target.refresh().is_ok() } else { self.target.answers() };
            // A refresh keeps the bus for some 25 ms: a button pressed meanwhile is taken now,
            // not a probe later.
            if let Some(p) = refresh.then(button).flatten() {
                return p;
            }
            match (answers, lost) {
                (false, _) => lost = true,
                (true, true) => {
                    defmt::warn!("the display lost power and answers again: drawing the frame again");
                    return Paused::Lost;
                }
                (true, false) => {}
            }
        }
        Paused::Elapsed
    }
}

/// How a press of a button ends a pause, if one was pressed since the last look
/// ([`crate::button`]).
fn button() -> Option<Paused> {
    use crate::button::Press;
    match crate::button::pressed()? {
        Press::Next => {
            defmt::info!("the button: the next scene");
            Some(Paused::Next)
        }
        Press::Turn if firmware::app::CAMERA_TURNS => {
            defmt::info!("the button: the camera turned");
            Some(Paused::Turn)
        }
        Press::Turn => {
            defmt::warn!(
                "the button: this image bakes its scenes for their own cameras (build with `parse` to turn them)"
            );
            None
        }
    }
}

/// The scene in the slot (`firmware::slot`), again and again: its frame, or a message on the
/// panel that says why there is none (the slot empty or corrupt, the scene refused at its line
/// and column or too big for the image's storage), also logged.
#[cfg(feature = "slot")]
pub fn run<T: DrawTarget<Color = Shown, Error = DisplayError> + SetUp + Send, L: OutputPin>(
    mut panel: Panel<'_, T, L>,
) -> ! {
    use firmware::slot::Message;
    // The camera's step around the scene (the camera-turn button).
    let mut step = 0;
    loop {
        let failed = match firmware::slot::text() {
            Ok(text) => match panel.show(text, &Shot::turned(step)) {
                Ok((r, micros)) => {
                    report(Record::Frame(frame_done(0, &r, micros)));
                    defmt::info!(
                        "slot: turn {}/{}: {} ms, rays {}, object tests {}",
                        step,
                        firmware::app::TURN_STEPS,
                        micros.0 / 1000,
                        r.stats.total_rays(),
                        r.stats.object_tests
                    );
                    None
                }
                Err(e) => Some(Message::of(e)),
            },
            Err(e) => Some(Message::of(e)),
        };
        if let Some(m) = failed {
            report(Record::Failed { scene: 0 });
            defmt::error!("slot: {}", m.as_str());
            if panel.message(m.as_str()).is_err() {
                defmt::error!("the display did not take the message");
            }
        }
        step = match panel.pause() {
            Paused::Turn => (step + 1) % firmware::app::TURN_STEPS,
            Paused::Next => 0,
            Paused::Elapsed | Paused::Lost => step,
        };
    }
}

/// The embedded scenes in turn, each frame's time and statistics logged.
#[cfg(not(any(feature = "orbit", feature = "ladder", feature = "slot")))]
pub fn run<T: DrawTarget<Color = Shown, Error = DisplayError> + SetUp + Send, L: OutputPin>(
    mut panel: Panel<'_, T, L>,
) -> ! {
    loop {
        for (i, (name, scene)) in EMBEDDED.iter().copied().enumerate() {
            // A frame the display did not take, or lost with its power, is drawn again once the
            // panel answers; the camera-turn button draws it from a step further around.
            let mut step = 0;
            loop {
                match show_scene(&mut panel, i, name, scene, step) {
                    Paused::Turn => step = (step + 1) % firmware::app::TURN_STEPS,
                    Paused::Lost => {}
                    Paused::Elapsed | Paused::Next => break,
                }
            }
        }
    }
}

/// Scene `i`'s frame from the camera's `step` around it, drawn again while the display does not
/// take it, then the pause after it ([`Panel::pause`]).
#[cfg(not(any(feature = "orbit", feature = "ladder", feature = "slot")))]
fn show_scene<T: DrawTarget<Color = Shown, Error = DisplayError> + SetUp + Send, L: OutputPin>(
    panel: &mut Panel<'_, T, L>,
    i: usize,
    name: &str,
    scene: Embedded,
    step: u32,
) -> Paused {
    while let Err(e) = panel.show(scene, &Shot::turned(step)).map(|(r, (us, setup_us))| {
        report(Record::Frame(frame_done(i, &r, (us, setup_us))));
        let (s, shares) = (r.stats, r.share_us);
        defmt::info!(
            "{} (turn {}): {} ms (tile shares {} us and {} us), rays {} (shadow {}, reflection {}, refraction {}), object tests {}, cells {}, lattice {} B, stack high-water {} B",
            name, step, us / 1000, shares[0], shares[1], s.total_rays(), s.rays[1], s.rays[2], s.rays[3], s.object_tests, s.cells_visited,
            r.lattice_bytes, stack::high_water()
        );
    }) {
        report(Record::Failed { scene: i as u8 });
        defmt::error!("{}: {}", name, e);
        // Only a display that did not take the frame is worth another try.
        if !matches!(e, AppError::Render(RenderError::Draw(_))) {
            break;
        }
    }
    panel.pause()
}

/// Orbit mode: the camera circles each scene, frame after frame, for one turn.
#[cfg(all(feature = "orbit", not(feature = "ladder")))]
pub fn run<T: DrawTarget<Color = Shown, Error = DisplayError> + SetUp + Send, L: OutputPin>(
    mut panel: Panel<'_, T, L>,
) -> ! {
    use firmware::app::ORBIT_FRAMES;
    loop {
        for (scene, (name, text)) in EMBEDDED.iter().copied().enumerate() {
            let t0 = panel.timer.get_counter();
            for i in 0..ORBIT_FRAMES {
                let shot = Shot { turn: i as f64 / ORBIT_FRAMES as f64, ..Shot::default() };
                if let Err(e) = panel.show(text, &shot) {
                    defmt::error!("{}: orbit frame {}: {}", name, i, e);
                    break;
                }
            }
            let us = (panel.timer.get_counter() - t0).to_micros().max(1);
            report(Record::Orbit { scene: scene as u8, frames: ORBIT_FRAMES, us, stack: stack::high_water() as u32 });
            let centi_fps = ORBIT_FRAMES as u64 * 100_000_000 / us;
            defmt::info!(
                "{}: orbit of {} frames in {} ms: {}.{=u64:02} frames per second, stack high-water {} B",
                name,
                ORBIT_FRAMES,
                us / 1000,
                centi_fps / 100,
                centi_fps % 100,
                stack::high_water()
            );
            let _ = panel.pause();
        }
    }
}

/// The ladder: the first scene once per rung, from the paper's method to the default.
#[cfg(feature = "ladder")]
pub fn run<T: DrawTarget<Color = Shown, Error = DisplayError> + SetUp + Send, L: OutputPin>(
    mut panel: Panel<'_, T, L>,
) -> ! {
    use firmware::app::{EMBEDDED, LADDER};
    loop {
        let (name, text) = EMBEDDED[0];
        for (rung, (what, tuning)) in LADDER.iter().enumerate() {
            match panel.show(text, &Shot { turn: 0.0, tuning: *tuning }) {
                Ok((r, (us, setup_us))) => {
                    report(Record::Rung { rung: rung as u8, frame: frame_done(0, &r, (us, setup_us)) });
                    defmt::info!(
                        "ladder {}: {}: {} us, shares {} us and {} us, object tests {}, cells {} ({})",
                        rung,
                        name,
                        us,
                        r.share_us[0],
                        r.share_us[1],
                        r.stats.object_tests,
                        r.stats.cells_visited,
                        what
                    )
                }
                Err(e) => {
                    report(Record::Failed { scene: 0 });
                    defmt::error!("ladder {}: {}: {}", rung, name, e)
                }
            }
        }
        let _ = panel.pause();
    }
}
