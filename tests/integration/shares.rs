//! A frame split into tile shares (one per core) gives, share by share, the pixels of the whole
//! frame; frames whose tiles depend on each other refuse to be split. Switching shadow-ray
//! coherence off (the paper's method as it was) changes work, never a pixel.

use crate::common;
use common::*;
use lattice_rt::render::RenderError;
use lattice_rt::scene::Object;
use lattice_rt::{
    dither_band, parse, render, render_pass, render_share, trace_pass, trace_share, BitFrame, Dither, Frame, Fx,
    HeapScratch, KeptTile, NoHooks, Real, Sampling, Share, Stats, Traced, Tracer,
};

/// Renders `name` into a fresh 1-bit frame for each frame in `frames`, all into one bitmap.
fn render_into<R: Real>(name: &str, frames: &[(Frame, Share)], coherence: bool) -> (Vec<u8>, Stats) {
    with_lattice::<R, _>(name, frames[0].0.size(), |scene, lat| {
        let mut tracer = Tracer::new(scene, lat);
        tracer.set_shadow_coherence(coherence);
        let (w, h) = (frames[0].0.width as u32, frames[0].0.height as u32);
        let mut bits = vec![0u8; BitFrame::bytes(w, h)];
        let mut target = BitFrame::new(w, h, &mut bits).unwrap();
        let mut stats = Stats::default();
        for (f, share) in frames {
            let mut scratch = HeapScratch::new(scene, f);
            let s = render_share(&tracer, f, *share, &mut target, &mut scratch.scratch(), &mut NoHooks).unwrap();
            stats.object_tests += s.object_tests;
            stats.rays[0] += s.rays[0];
        }
        (bits, stats)
    })
}

fn shares_of(frame: Frame, of: u8) -> Vec<(Frame, Share)> {
    (0..of).map(|index| (frame, Share { index, of })).collect()
}

#[test]
fn shares_rendered_apart_give_the_whole_frame() {
    for name in ["chair", "spheres", "whitted"] {
        for sampling in [
            Sampling::Center,
            Sampling::Adaptive { contrast: 4, coarse: false },
            Sampling::Adaptive { contrast: 4, coarse: true },
        ] {
            // Silhouette lines too: each tile traces its own apron, so they split like the rest.
            for outline in [false, true] {
                // 100x60: the last tile column and row are partial.
                let frame = Frame { sampling, outline, ..Frame::new(100, 60) };
                let (whole, ws) = render_into::<Fx>(name, &[(frame, Share::ALL)], true);
                for of in [2, 3] {
                    let (split, ss) = render_into::<Fx>(name, &shares_of(frame, of), true);
                    assert_eq!(whole, split, "{name}, {sampling:?}, outline {outline}, {of} shares");
                    assert_eq!(ws.rays[0], ss.rays[0], "{name}, {sampling:?}: every eye ray traced once");
                }
                // And bands of tile rows.
                let bands: Vec<(Frame, Share)> =
                    [(0, 3), (3, 5), (5, 8)].map(|rows| (Frame { rows, ..frame }, Share::ALL)).to_vec();
                assert_eq!(
                    whole,
                    render_into::<Fx>(name, &bands, true).0,
                    "{name}, {sampling:?}, outline {outline}, bands"
                );
            }
        }
    }
}

#[test]
fn a_share_holds_a_checkerboard_of_tiles() {
    let (a, b) = (Share { index: 0, of: 2 }, Share { index: 1, of: 2 });
    for ty in 0..8 {
        for tx in 0..16 {
            assert!(a.holds(tx, ty) != b.holds(tx, ty));
            assert_eq!(a.holds(tx, ty), (tx + ty) % 2 == 0);
        }
    }
    assert!(Share::ALL.holds(5, 3));
}

#[test]
fn frames_that_carry_error_between_tiles_or_bad_shares_are_refused() {
    let text = scene_text("chair");
    let mut storage = vec![Object::<f64>::default(); 64];
    let mut parts = lattice_rt::Parts::default();
    let scene = parse::<f64>(&text, &mut storage, &mut parts).unwrap();
    let tracer = Tracer::new(&scene, &lattice_rt::BruteForce);
    let mut bits = vec![0u8; BitFrame::bytes(64, 32)];
    let mut target = BitFrame::new(64, 32, &mut bits).unwrap();
    let refused = [
        (Frame { dither: Dither::FloydSteinberg, ..Frame::new(64, 32) }, Share { index: 0, of: 2 }),
        (Frame::new(64, 32), Share { index: 2, of: 2 }),
        (Frame::new(64, 32), Share { index: 0, of: 0 }),
    ];
    for (f, share) in refused {
        let mut scratch = HeapScratch::new(&scene, &f);
        let r = render_share(&tracer, &f, share, &mut target, &mut scratch.scratch(), &mut NoHooks);
        assert!(matches!(r, Err(RenderError::BadShare)), "{f:?}, {share:?}: {r:?}");
    }
    // Error diffusion over the whole frame is fine.
    let f = Frame { dither: Dither::FloydSteinberg, ..Frame::new(64, 32) };
    let mut scratch = HeapScratch::new(&scene, &f);
    assert!(render(&tracer, &f, &mut target, &mut scratch.scratch(), &mut NoHooks).is_ok());
}

#[test]
fn shadow_coherence_changes_work_not_pixels() {
    for name in ["chair", "desk", "polyhedron", "spheres", "whitted"] {
        let frame = Frame::new(96, 48);
        let (with, ws) = render_into::<f64>(name, &[(frame, Share::ALL)], true);
        let (without, wo) = render_into::<f64>(name, &[(frame, Share::ALL)], false);
        assert_eq!(with, without, "{name}");
        assert!(
            ws.object_tests <= wo.object_tests,
            "{name}: {} tests with coherence, {} without",
            ws.object_tests,
            wo.object_tests
        );
    }
}

#[test]
fn shares_count_their_tiles_as_the_checkerboard_holds_them() {
    for of in 1..=3u8 {
        for index in 0..of {
            let share = Share { index, of };
            for (tiles_x, rows) in [(16, (0, 8)), (5, (2, 7)), (1, (0, 1)), (7, (3, 3))] {
                let counted = (rows.0..rows.1)
                    .flat_map(|ty| (0..tiles_x).map(move |tx| (tx, ty)))
                    .filter(|&(tx, ty)| share.holds(tx, ty))
                    .count();
                assert_eq!(
                    share.tiles_in(tiles_x, rows),
                    counted,
                    "share {index} of {of}, {tiles_x} tiles wide, rows {rows:?}"
                );
            }
        }
    }
    // The 128x64 board frame in 8x8 tiles: 64 tiles a share, 16 kept rays a tile.
    let frame = Frame::new(128, 64);
    assert_eq!(frame.traced_len(Share { index: 0, of: 2 }), 64 * 16);
    assert_eq!(frame.traced_len(Share { index: 1, of: 2 }), 64 * 16);
    assert_eq!(frame.traced_len(Share::ALL), 128 * 16);
}

/// Trace, then dither: shares trace a frame's bands into kept levels (`trace_share`), and the
/// bands dithered in order (`dither_band`) are the frame `render` draws, bit for bit, with
/// error diffusion too (which cannot be shared out any other way). With `part` tiles, each band
/// is dithered in parts of that many tiles (`dither_tiles`, as the two-core board dithers the
/// tiles traced so far); with none, whole (`dither_band`).
fn traced_then_dithered<R: Real>(name: &str, frame: Frame, of: u8, part: Option<usize>) -> Vec<u8> {
    with_lattice::<R, _>(name, frame.size(), |scene, lat| {
        let tracer = Tracer::new(scene, lat);
        let (w, h) = (frame.width as u32, frame.height as u32);
        let mut bits = vec![0u8; BitFrame::bytes(w, h)];
        let mut target = BitFrame::new(w, h, &mut bits).unwrap();
        let mut carries = vec![0i16; lattice_rt::dither::Ditherer::rows_len(frame.dither, w as usize)];
        let mut ditherer = lattice_rt::dither::Ditherer::new(frame.dither, w as usize, &mut carries).unwrap();
        let bands = (h as usize).div_ceil(frame.tile as usize) as u16;
        let mut above = vec![(0u16, 0u16); w as usize];
        let mut band_bits = vec![embedded_graphics::pixelcolor::BinaryColor::Off; w as usize * frame.tile as usize];
        for ty in 0..bands {
            let band = Frame { rows: (ty, ty + 1), ..frame };
            let kept: Vec<Vec<KeptTile>> = (0..of)
                .map(|index| {
                    let share = Share { index, of };
                    let mut kept = vec![KeptTile::EMPTY; band.tiles_len(share)];
                    let mut scratch = HeapScratch::new(scene, &band);
                    trace_share(&tracer, &band, share, &mut kept, &mut scratch.scratch(), &mut NoHooks).unwrap();
                    kept
                })
                .collect();
            // Share s holds the tiles tx = s - ty (mod of) of this row: tile tx is its (tx / of)-th.
            let tile = |tx: usize| kept[(tx + ty as usize) % of as usize].get(tx / of as usize);
            match part {
                None => {
                    dither_band(&frame, ty as usize, tile, (&mut above, &mut band_bits), &mut ditherer, &mut target)
                        .unwrap()
                }
                Some(part) => {
                    let (tiles, mut from, mut left) =
                        ((w as usize).div_ceil(frame.tile as usize), 0, [(0, 0); lattice_rt::dither::MAX_TILE]);
                    while from < tiles {
                        let upto = |tx: usize| if tx < from + part { tile(tx) } else { None };
                        let next = lattice_rt::dither_tiles(
                            &frame,
                            (ty as usize, from),
                            upto,
                            (&mut above, &mut band_bits, &mut left),
                            &mut ditherer,
                            &mut target,
                        )
                        .unwrap();
                        assert_eq!(next, (from + part).min(tiles), "a part ends where its tiles end");
                        from = next;
                    }
                }
            }
        }
        bits
    })
}

#[test]
fn traced_shares_dithered_in_order_give_the_whole_frame() {
    for name in ["chair", "desk", "whitted"] {
        let samplings = [Sampling::Adaptive { contrast: 4, coarse: true }, Sampling::Center, Sampling::Grid2x2];
        for (dither, sampling) in
            [Dither::FloydSteinberg, Dither::Atkinson, Dither::BlueNoise].into_iter().zip(samplings)
        {
            for (width, height, outline, tile) in
                [(128, 64, true, 8), (100, 60, true, 8), (100, 60, false, 8), (128, 64, true, 16), (100, 60, true, 16)]
            {
                let frame = Frame { dither, outline, sampling, tile, ..Frame::new(width, height) };
                let (whole, _) = render_into::<Fx>(name, &[(frame, Share::ALL)], true);
                // 1 to 3 shares, and one tile at a time (`Share::single`: as many shares as tiles
                // across), each band dithered whole; one tile at a time, dithered in parts of
                // one and of three tiles.
                let across = (width as usize).div_ceil(tile as usize) as u8;
                for (of, part) in
                    [(1, None), (2, None), (3, None), (across, None), (across, Some(1)), (across, Some(3))]
                {
                    assert_eq!(whole, traced_then_dithered::<Fx>(name, frame, of, part), "{name}, {dither:?}, {sampling:?}, {width}x{height}, {tile}x{tile} tiles, lines {outline}, {of} shares, parts of {part:?} tiles");
                }
                assert_eq!(Share::single(5, 3, 16), Share { index: 8, of: 16 });
            }
        }
    }
    let frame = Frame { dither: Dither::FloydSteinberg, outline: true, ..Frame::new(128, 64) };
    assert_eq!(
        render_into::<f32>("spheres", &[(frame, Share::ALL)], true).0,
        traced_then_dithered::<f32>("spheres", frame, 2, None),
        "f32"
    );
    // Lines need the row above: too short a row is refused, not drawn without them.
    let mut carries = vec![0i16; lattice_rt::dither::Ditherer::rows_len(frame.dither, 128)];
    let mut ditherer = lattice_rt::dither::Ditherer::new(frame.dither, 128, &mut carries).unwrap();
    let mut bits = vec![0u8; BitFrame::bytes(128, 64)];
    let mut target = BitFrame::new(128, 64, &mut bits).unwrap();
    let kept = KeptTile::EMPTY;
    let mut band_bits = [embedded_graphics::pixelcolor::BinaryColor::Off; 128 * 8];
    let err = dither_band(&frame, 1, |_| Some(&kept), (&mut [(0, 0); 100], &mut band_bits), &mut ditherer, &mut target)
        .unwrap_err();
    assert_eq!(err, RenderError::ScratchTooSmall { needed: 128 });
    let err = dither_band(
        &frame,
        1,
        |_| Some(&kept),
        (&mut [(0, 0); 128], &mut band_bits[..1000]),
        &mut ditherer,
        &mut target,
    )
    .unwrap_err();
    assert_eq!(err, RenderError::ScratchTooSmall { needed: 1024 });
}

/// The passes of a progressive frame traced tile by tile (`trace_pass`, each tile its own
/// share and its own rays between passes, as the two-core board takes them) and each band
/// dithered in order (`dither_band`, lines on the last pass alone) are the pictures
/// `render_pass` draws, pass by pass, bit for bit.
#[test]
fn traced_passes_dithered_in_order_give_every_pass() {
    for name in ["chair", "whitted"] {
        with_lattice::<Fx, _>(name, [128, 64], |scene, lat| {
            let tracer = Tracer::new(scene, lat);
            let frame = Frame {
                dither: Dither::BlueNoise,
                outline: true,
                sampling: Sampling::Adaptive { contrast: 4, coarse: true },
                ..Frame::new(128, 64)
            };
            let (w, h) = (128u32, 64u32);
            // What render_pass draws, pass by pass.
            let mut want = Vec::new();
            let mut bits = vec![0u8; BitFrame::bytes(w, h)];
            let mut traced = vec![Traced::default(); frame.traced_len(Share::ALL)];
            for pass in [8, 4, 2, 1] {
                let mut target = BitFrame::new(w, h, &mut bits).unwrap();
                let mut scratch = HeapScratch::new(scene, &frame);
                render_pass(
                    &tracer,
                    &frame,
                    Share::ALL,
                    pass,
                    &mut traced,
                    &mut target,
                    &mut scratch.scratch(),
                    &mut NoHooks,
                )
                .unwrap();
                want.push(bits.clone());
            }
            {
                // Each tile keeps its own rays between passes (16 per 8x8 tile), as the board's do.
                let mut traced = vec![vec![Traced::default(); 16]; frame.tiles_len(Share::ALL)];
                for (k, pass) in [8, 4, 2, 1].into_iter().enumerate() {
                    let mut bits = vec![0u8; BitFrame::bytes(w, h)];
                    let mut target = BitFrame::new(w, h, &mut bits).unwrap();
                    let shown = Frame { outline: frame.outline && pass == 1, ..frame };
                    let mut carries = vec![0i16; lattice_rt::dither::Ditherer::rows_len(frame.dither, w as usize)];
                    let mut ditherer =
                        lattice_rt::dither::Ditherer::new(frame.dither, w as usize, &mut carries).unwrap();
                    let mut above = vec![(0u16, 0u16); w as usize];
                    let mut band_bits = vec![embedded_graphics::pixelcolor::BinaryColor::Off; w as usize * 8];
                    for ty in 0..(h / 8) as u16 {
                        let band = Frame { rows: (ty, ty + 1), ..frame };
                        // The band's tiles in `of` shares, each tile traced alone (`Share::single`).
                        let tiles_x = 16;
                        let kept: Vec<KeptTile> = (0..tiles_x)
                            .map(|tx| {
                                let share = Share::single(tx, ty as usize, tiles_x);
                                let mut kept = [KeptTile::EMPTY];
                                let mut scratch = HeapScratch::new(scene, &band);
                                let rays = &mut traced[ty as usize * tiles_x + tx];
                                trace_pass(
                                    &tracer,
                                    &band,
                                    share,
                                    pass,
                                    rays,
                                    &mut kept,
                                    &mut scratch.scratch(),
                                    &mut NoHooks,
                                )
                                .unwrap();
                                kept[0]
                            })
                            .collect();
                        let tile = |tx: usize| kept.get(tx);
                        dither_band(
                            &shown,
                            ty as usize,
                            tile,
                            (&mut above, &mut band_bits),
                            &mut ditherer,
                            &mut target,
                        )
                        .unwrap();
                    }
                    assert_eq!(bits, want[k], "{name}, pass {pass}");
                }
            }
            // A frame that cannot be progressive, or a pass that is not one, is refused.
            let mut kept = vec![KeptTile::EMPTY; frame.tiles_len(Share::ALL)];
            let mut scratch = HeapScratch::new(scene, &frame);
            let err = trace_pass(
                &tracer,
                &frame,
                Share::ALL,
                3,
                &mut traced,
                &mut kept,
                &mut scratch.scratch(),
                &mut NoHooks,
            )
            .unwrap_err();
            assert_eq!(err, RenderError::NotProgressive);
        });
    }
}
