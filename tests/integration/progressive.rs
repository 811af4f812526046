//! Progressive frames (`render_pass`): the passes 8, 4, 2 and 1 trace every eye ray of the
//! plain frame exactly once between them (and, with two-level adaptive sampling, the rays of
//! the previews' every second pixel that the plain frame fills), the last pass draws exactly the plain frame (for
//! every sampling and dither that allows passes, in shares too), and each preview pass shows
//! its blocks flat.

use crate::common;
use common::*;
use lattice_rt::render::RenderError;
use lattice_rt::scene::Object;
use lattice_rt::{
    parse, render_pass, render_share, BitFrame, Dither, Frame, Fx, HeapScratch, NoHooks, Real, Sampling, Share, Tone,
    Traced, Tracer,
};

/// The frames of each pass (shares rendered one after the other into one bitmap), the eye rays
/// of all passes, and the plain frame with its eye rays.
fn passes<R: Real>(name: &str, frame: Frame, of: u8) -> (Vec<Vec<u8>>, u64, Vec<u8>, u64) {
    with_lattice::<R, _>(name, frame.size(), |scene, lat| {
        let tracer = Tracer::new(scene, lat);
        let (w, h) = (frame.width as u32, frame.height as u32);
        let shares: Vec<Share> = (0..of).map(|index| Share { index, of }).collect();
        let mut traced: Vec<Vec<Traced>> =
            shares.iter().map(|s| vec![Traced::default(); frame.traced_len(*s)]).collect();
        let (mut frames, mut rays) = (Vec::new(), 0);
        for pass in [8u8, 4, 2, 1] {
            let mut bits = vec![0u8; BitFrame::bytes(w, h)];
            let mut target = BitFrame::new(w, h, &mut bits).unwrap();
            for (s, kept) in shares.iter().zip(traced.iter_mut()) {
                let mut scratch = HeapScratch::new(scene, &frame);
                rays += render_pass(&tracer, &frame, *s, pass, kept, &mut target, &mut scratch.scratch(), &mut NoHooks)
                    .unwrap()
                    .rays[0];
            }
            frames.push(bits);
        }
        let mut plain = vec![0u8; BitFrame::bytes(w, h)];
        let mut target = BitFrame::new(w, h, &mut plain).unwrap();
        let mut scratch = HeapScratch::new(scene, &frame);
        let stats =
            render_share(&tracer, &frame, Share::ALL, &mut target, &mut scratch.scratch(), &mut NoHooks).unwrap();
        (frames, rays, plain, stats.rays[0])
    })
}

#[test]
fn the_last_pass_is_the_plain_frame_and_no_eye_ray_is_traced_twice() {
    let samplings = [
        Sampling::Center,
        Sampling::Adaptive { contrast: 4, coarse: false },
        Sampling::Adaptive { contrast: 4, coarse: true },
        Sampling::Edges { contrast: 16 },
    ];
    for name in ["chair", "whitted", "desk"] {
        for sampling in samplings {
            for dither in [Dither::Bayer, Dither::BlueNoise, Dither::FloydSteinberg] {
                for outline in [false, true] {
                    // 100x60: partial tiles at the right and bottom.
                    let frame =
                        Frame { sampling, dither, outline, tone: Tone { gamma_tenths: 8 }, ..Frame::new(100, 60) };
                    let of = if frame.bands_independent() { 2 } else { 1 };
                    let (frames, rays, plain, plain_rays) = passes::<Fx>(name, frame, of);
                    let what = format!("{name} {sampling:?} {dither:?} outline {outline}");
                    assert_eq!(frames[3], plain, "{what}");
                    if sampling == (Sampling::Adaptive { contrast: 4, coarse: true }) {
                        // The previews trace every second pixel of every second line, which the
                        // plain frame's coarse level partly fills: at most those rays more.
                        let halves = |n: u16| {
                            (0..n)
                                .step_by(frame.tile as usize)
                                .map(|a| u64::from((n - a).min(u16::from(frame.tile))).div_ceil(2))
                                .sum::<u64>()
                        };
                        let previews = halves(frame.width) * halves(frame.height);
                        assert!(
                            plain_rays < rays && rays <= plain_rays + previews,
                            "{what}: {rays} rays, plain {plain_rays}, previews {previews}"
                        );
                    } else {
                        assert_eq!(rays, plain_rays, "{what}");
                    }
                }
            }
        }
    }
    let (frames, _, plain, _) = passes::<f32>("spheres", Frame::new(64, 32), 1);
    assert_eq!(frames[3], plain);
}

#[test]
fn the_first_pass_traces_one_ray_per_8x8_block() {
    let frame = Frame { dither: Dither::Pattern(8), ..Frame::new(128, 64) };
    // Pattern 8 shows one ray per block flat: the first pass of a Bayer frame traces the same
    // number of rays (one per block), a 64th of the frame's.
    let (_, _, _, pattern_rays) = passes_plain::<Fx>("chair", frame);
    let (frames, _, _, plain_rays) = passes::<Fx>("chair", Frame::new(128, 64), 1);
    assert_eq!(pattern_rays * 64, plain_rays);
    assert_eq!(frames.len(), 4);
}

/// The plain frame alone (for frames that cannot be rendered progressively).
fn passes_plain<R: Real>(name: &str, frame: Frame) -> (Vec<u8>, u64, Vec<u8>, u64) {
    let (bits, stats) = render_text::<R>(&scene_text(name), Accel::Lattice, &frame);
    (Vec::new(), 0, bits, stats.rays[0])
}

#[test]
fn frames_that_cannot_be_progressive_are_refused() {
    let text = scene_text("chair");
    let mut storage = vec![Object::<Fx>::default(); 64];
    let mut parts = lattice_rt::Parts::default();
    let scene = parse::<Fx>(&text, &mut storage, &mut parts).unwrap();
    let tracer = Tracer::new(&scene, &lattice_rt::BruteForce);
    let mut bits = vec![0u8; BitFrame::bytes(64, 32)];
    let mut target = BitFrame::new(64, 32, &mut bits).unwrap();
    for (frame, pass, room) in [
        (Frame { dither: Dither::Pattern(4), ..Frame::new(64, 32) }, 8u8, true),
        (Frame { tile: 4, ..Frame::new(64, 32) }, 8, true),
        (Frame { tile: 0, ..Frame::new(64, 32) }, 8, true),
        (Frame { tile: 24, ..Frame::new(64, 32) }, 8, true),
        (Frame::new(64, 32), 3, true),
        (Frame::new(64, 32), 8, false),
    ] {
        let n = if room { frame.traced_len(Share::ALL) } else { frame.traced_len(Share::ALL) - 1 };
        let mut traced = vec![Traced::default(); n];
        let mut scratch = HeapScratch::new(&scene, &frame);
        let r = render_pass(
            &tracer,
            &frame,
            Share::ALL,
            pass,
            &mut traced,
            &mut target,
            &mut scratch.scratch(),
            &mut NoHooks,
        );
        assert!(matches!(r, Err(RenderError::NotProgressive)), "{frame:?} pass {pass}");
    }
}
