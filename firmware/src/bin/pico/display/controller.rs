//! The OLED controllers with page-organised RAM the firmware drives, one chosen by a feature:
//! the SSD1306 (default; on 128x32 glass with `ssd1306-128x32`, on 72x40 glass with
//! `ssd1306-72x40`), the SH1106 (`sh1106`: the common 1.3" 128x64 modules) and the SSD1309
//! (`ssd1309`: the 2.42" modules). Each is its set-up, sent command by command, and how
//! an area of pages is addressed. They share the bus (`display-interface`: the control byte on
//! I2C, D/C# on SPI) and the page layout (a byte is 8 rows of one column, LSB on top), so one
//! draw target serves all three. (The `ssd1306` crate drives only the SSD1306: it sends a
//! charge-pump command the SSD1309 lacks and horizontal addressing, which the SH1106 lacks; the
//! `sh1106` crate keeps a frame buffer and speaks embedded-hal 0.2. The set-up below is the
//! `ssd1306` crate's own for the SSD1306, byte for byte.)

// Every image holds the three tables and drives the one its features choose.
#![allow(dead_code)]

/// How a draw area's bytes reach the controller's RAM.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum Addressing {
    /// Horizontal addressing within a column and page window (SSD1306, SSD1309): the window
    /// (0x21, 0x22), then every page's bytes in one transfer.
    Window,
    /// Page addressing only (SH1106): each page of the area its page and column (0xB0, 0x0_,
    /// 0x1_), then its bytes.
    Pages,
}

/// A controller as a module wires it.
pub struct Controller {
    /// Its name in the log.
    pub name: &'static str,
    /// The commands that set it up from any state (a panel that lost power included), each with
    /// its arguments and sent as its own transfer, display on last; in runs the tables share.
    pub set_up: &'static [&'static [&'static [u8]]],
    /// How a draw area is addressed.
    pub addressing: Addressing,
    /// The RAM column of the panel's first column (the SH1106's 132 columns drive a 128-column
    /// glass from column 2).
    pub column_offset: u8,
}

/// The display clock (0xD5): the oscillator setting in the high nibble, the divide ratio less
/// one in the low. Its reset value (0x80) on the 1-bit images; the gray mode's subframes want the
/// fastest refresh, so it runs the oscillator at its highest setting, undivided (0xF0), as the
/// Thumby's grayscale library does.
pub const CLOCK: u8 = if cfg!(feature = "gray") { 0xf0 } else { 0x80 };
/// The SSD1306's pre-charge periods (0xD9): phase 2 in the high nibble, phase 1 in the low, in
/// display clocks (the `ssd1306` crate's 0x21).
pub const PRECHARGE: u8 = 0x21;
/// Display off: every set-up's first command.
pub const DISPLAY_OFF: &[u8] = &[0xae];
/// Display on: every set-up's last command.
pub const DISPLAY_ON: &[u8] = &[0xaf];
/// Display off and the oscillator at [`CLOCK`]: every set-up's first commands.
const HEAD: &[&[u8]] = &[DISPLAY_OFF, &[0xd5, CLOCK]];
/// No offset, start line 0, the SSD1306's charge pump on and horizontal addressing.
const SSD1306_PUMP: &[&[u8]] = &[&[0xd3, 0], &[0x40], &[0x8d, 0x14], &[0x20, 0x00]];
/// Segment remap and reversed COM scan (upright), the SSD1306's pre-charge, contrast and VCOMH
/// (the `ssd1306` crate's), the RAM shown as it is, no scrolling, display on.
const SSD1306_TAIL: &[&[u8]] =
    &[&[0xa1], &[0xc8], &[0xd9, PRECHARGE], &[0x81, 0x5f], &[0xdb, 0x40], &[0xa4], &[0xa6], &[0x2e], DISPLAY_ON];

/// The SSD1306, 128x64 (the `ssd1306` crate's set-up: horizontal addressing, charge pump on,
/// segment remap and reversed COM scan, contrast 0x5F).
pub const SSD1306: Controller = Controller {
    name: "SSD1306",
    set_up: &[HEAD, &[&[0xa8, 63]], SSD1306_PUMP, &[&[0xda, 0x12]], SSD1306_TAIL],
    addressing: Addressing::Window,
    column_offset: 0,
};

/// The SSD1306 on a 0.91" 128x32 module: 32 multiplexed rows, COM pins in sequence (0xDA 0x02).
pub const SSD1306_128X32: Controller = Controller {
    name: "SSD1306 (128x32)",
    set_up: &[HEAD, &[&[0xa8, 31]], SSD1306_PUMP, &[&[0xda, 0x02]], SSD1306_TAIL],
    addressing: Addressing::Window,
    column_offset: 0,
};

/// The SSD1306 on a 0.42" 72x40 module (the Thumby's panel): 40 multiplexed rows, the glass on
/// RAM columns 28 to 99, the internal current reference on (0xAD 0x30), as the `ssd1306`
/// crate sets it up.
pub const SSD1306_72X40: Controller = Controller {
    name: "SSD1306 (72x40)",
    set_up: &[HEAD, &[&[0xa8, 39]], SSD1306_PUMP, &[&[0xda, 0x12], &[0xad, 0x30]], SSD1306_TAIL],
    addressing: Addressing::Window,
    column_offset: 28,
};

/// The SH1106 on a 128x64 module (datasheet V2.3): page addressing, DC-DC on (0xAD 0x8B), pump
/// at 8.0 V, the glass on columns 2 to 129.
pub const SH1106: Controller = Controller {
    name: "SH1106",
    set_up: &[
        HEAD,
        &[&[0xa8, 63], &[0xd3, 0], &[0x40], &[0xad, 0x8b], &[0x32], &[0xda, 0x12], &[0xa1], &[0xc8]],
        &[&[0xd9, 0x22], &[0x81, 0x80], &[0xdb, 0x35], &[0xa4], &[0xa6], DISPLAY_ON],
    ],
    addressing: Addressing::Pages,
    column_offset: 2,
};

/// The SSD1309 on a 128x64 module (datasheet rev 1.2): as the SSD1306 but with no charge pump
/// (the module's supply makes VCC), its own pre-charge and VCOMH levels.
pub const SSD1309: Controller = Controller {
    name: "SSD1309",
    set_up: &[
        HEAD,
        &[&[0xa8, 63], &[0xd3, 0], &[0x40], &[0x20, 0x00], &[0xda, 0x12], &[0xa1], &[0xc8]],
        &[&[0xd9, 0x22], &[0x81, 0x7f], &[0xdb, 0x34], &[0xa4], &[0xa6], &[0x2e], DISPLAY_ON],
    ],
    addressing: Addressing::Window,
    column_offset: 0,
};

/// The controller this image drives.
#[cfg(not(any(feature = "sh1106", feature = "ssd1309", feature = "ssd1306-128x32", feature = "ssd1306-72x40")))]
pub const PANEL: Controller = SSD1306;
/// The controller this image drives.
#[cfg(feature = "ssd1306-128x32")]
pub const PANEL: Controller = SSD1306_128X32;
/// The controller this image drives.
#[cfg(feature = "ssd1306-72x40")]
pub const PANEL: Controller = SSD1306_72X40;
/// The controller this image drives.
#[cfg(feature = "sh1106")]
pub const PANEL: Controller = SH1106;
/// The controller this image drives.
#[cfg(feature = "ssd1309")]
pub const PANEL: Controller = SSD1309;

#[cfg(any(
    all(feature = "sh1106", feature = "ssd1309"),
    all(feature = "ssd1306-128x32", feature = "ssd1306-72x40"),
    all(any(feature = "sh1106", feature = "ssd1309"), any(feature = "ssd1306-128x32", feature = "ssd1306-72x40"))
))]
compile_error!(
    "choose one panel: `sh1106`, `ssd1309`, `ssd1306-128x32` or `ssd1306-72x40` (or none: the SSD1306 128x64)"
);

/// A command that changes nothing shown (normal, not inverted, display): the probe of a panel
/// between frames.
pub const PROBE: &[u8] = &[0xa6];

/// The two commands (column window, page window) that address a draw area of `width` columns
/// from column `x0`, pages `p0` to `p1` (inclusive), with [`Addressing::Window`].
pub fn window(x0: u8, width: u8, p0: u8, p1: u8) -> ([u8; 3], [u8; 3]) {
    let c0 = x0 + PANEL.column_offset;
    ([0x21, c0, c0 + width - 1], [0x22, p0, p1])
}

/// The command that starts page `page` at column `x0` with [`Addressing::Pages`].
pub fn page_start(x0: u8, page: u8) -> [u8; 3] {
    let c = x0 + PANEL.column_offset;
    [0xb0 | page, c & 0x0f, 0x10 | (c >> 4)]
}
