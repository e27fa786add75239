//! Pictures as a list of shapes (polygons, lines, dots, text) that is written
//! either as SVG or, by a small rasterizer of its own, as PNG: the same list
//! gives the same picture in both formats. The rasterizer samples each pixel
//! on a 3 × 3 grid (anti-aliasing by supersampling) and paints shapes in
//! order, so later shapes cover earlier ones, as in SVG.

use std::fmt::Write as _;
use std::path::Path;

use glam::DVec2;

mod font;

/// An opaque colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Rgb(pub u8, pub u8, pub u8);

impl Rgb {
    /// White.
    pub const WHITE: Rgb = Rgb(255, 255, 255);
    /// Black.
    pub const BLACK: Rgb = Rgb(0, 0, 0);

    fn hex(self) -> String {
        format!("#{:02x}{:02x}{:02x}", self.0, self.1, self.2)
    }
}

/// Where a text's position is: at its start, middle or end.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Anchor {
    /// The text starts at the position.
    Start,
    /// The text is centred on the position.
    Middle,
    /// The text ends at the position.
    End,
}

/// One thing to paint; coordinates in pixels, y down.
#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    /// A filled polygon, optionally outlined.
    Polygon {
        /// Its corners.
        points: Vec<DVec2>,
        /// Fill colour.
        fill: Rgb,
        /// Outline colour and width.
        stroke: Option<(Rgb, f64)>,
    },
    /// A straight line with round ends.
    Line {
        /// One end.
        from: DVec2,
        /// The other end.
        to: DVec2,
        /// Colour.
        color: Rgb,
        /// Width.
        width: f64,
    },
    /// A filled disc.
    Dot {
        /// Centre.
        center: DVec2,
        /// Radius.
        radius: f64,
        /// Colour.
        fill: Rgb,
    },
    /// One line of monospace text; each character is [`Canvas::char_width`]
    /// × `scale` wide.
    Text {
        /// Anchor point, on the middle of the text's height.
        at: DVec2,
        /// Size: 1 is the font's 8 × 8 pixel cell.
        scale: u32,
        /// Colour.
        color: Rgb,
        /// Which point of the text `at` is.
        anchor: Anchor,
        /// The text (non-ASCII characters are drawn as `?` in PNG).
        text: String,
    },
}

/// A picture: a size, a background and shapes painted in order.
#[derive(Clone, Debug, PartialEq)]
pub struct Canvas {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Background colour.
    pub background: Rgb,
    /// Shapes, painted first to last.
    pub shapes: Vec<Shape>,
}

/// The file formats a [`Canvas`] can be written in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    /// Scalable vector graphics (text).
    Svg,
    /// Portable network graphics (8-bit RGB).
    Png,
}

impl Format {
    /// The format a picture's name asks for, in any case: PNG for `.png`,
    /// SVG for `.svg` or a name without an extension (`-`, `/dev/stdout`),
    /// either one also before `.gz` (the file is then compressed as it is
    /// written); `None` for any other extension (`.jpg`, `.pdf`): delmesh
    /// draws no other format, and a picture written under such a name
    /// would not be what the name says.
    pub fn of_path(path: &Path) -> Option<Format> {
        let name = path.file_name().map(|n| n.to_string_lossy().to_ascii_lowercase());
        let name = name.as_deref().unwrap_or("");
        let name = name.strip_suffix(".gz").unwrap_or(name);
        match Path::new(name).extension().and_then(|e| e.to_str()) {
            None => Some(Format::Svg),
            Some("svg") => Some(Format::Svg),
            Some("png") => Some(Format::Png),
            Some(_) => None,
        }
    }

    /// [`Format::of_path`], or the one-line refusal of a name it does not
    /// know (naming the picture as `what`: `--chart out.jpg`).
    pub fn of_picture(path: &Path, what: &str) -> Result<Format, String> {
        Format::of_path(path).ok_or_else(|| {
            format!("{what}: delmesh draws SVG and PNG pictures only: name it .svg or .png (.gz after it compresses)")
        })
    }
}

/// Samples per pixel along each axis when rasterizing (fewer for pictures
/// wider than [`MAX_SAMPLES`] / 3).
const SUPERSAMPLE: usize = 3;
/// At most this many samples along a side: bounds the rasterizer's memory
/// (8192² samples, 200 MB).
const MAX_SAMPLES: usize = 8192;
/// The largest picture side rasterized; larger canvases are cropped.
pub const MAX_SIDE: u32 = MAX_SAMPLES as u32;

impl Canvas {
    /// Width of one character of text at scale 1, in pixels.
    pub const CHAR_WIDTH: f64 = 8.0;

    /// An empty picture.
    pub fn new(width: u32, height: u32, background: Rgb) -> Self {
        Canvas {
            width,
            height,
            background,
            shapes: Vec::new(),
        }
    }

    /// Width of `text` at `scale`, in pixels.
    pub fn char_width(text: &str, scale: u32) -> f64 {
        text.chars().count() as f64 * Self::CHAR_WIDTH * scale as f64
    }

    /// Adds a shape on top of the others.
    pub fn push(&mut self, shape: Shape) {
        self.shapes.push(shape);
    }

    /// The picture in `format`.
    pub fn encode(&self, format: Format) -> std::io::Result<Vec<u8>> {
        match format {
            Format::Svg => Ok(self.to_svg().into_bytes()),
            Format::Png => self.to_png(),
        }
    }

    /// The picture as an SVG document.
    pub fn to_svg(&self) -> String {
        let mut s = String::new();
        let _ = writeln!(
            s,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{w}\" height=\"{h}\" viewBox=\"0 0 {w} {h}\">\n<rect width=\"100%\" height=\"100%\" fill=\"{}\"/>",
            self.background.hex(),
            w = self.width,
            h = self.height
        );
        for shape in &self.shapes {
            match shape {
                Shape::Polygon { points, fill, stroke } => {
                    s.push_str("<polygon points=\"");
                    for (k, p) in points.iter().enumerate() {
                        let _ = write!(s, "{}{:.1},{:.1}", if k > 0 { " " } else { "" }, p.x, p.y);
                    }
                    let _ = write!(s, "\" fill=\"{}\"", fill.hex());
                    if let Some((c, w)) = stroke {
                        let _ = write!(
                            s,
                            " stroke=\"{}\" stroke-width=\"{w}\" stroke-linejoin=\"round\"",
                            c.hex()
                        );
                    }
                    s.push_str("/>\n");
                }
                Shape::Line { from, to, color, width } => {
                    let _ = writeln!(
                        s,
                        "<line x1=\"{:.1}\" y1=\"{:.1}\" x2=\"{:.1}\" y2=\"{:.1}\" stroke=\"{}\" stroke-width=\"{width}\" stroke-linecap=\"round\"/>",
                        from.x,
                        from.y,
                        to.x,
                        to.y,
                        color.hex()
                    );
                }
                Shape::Dot { center, radius, fill } => {
                    let _ = writeln!(
                        s,
                        "<circle cx=\"{:.1}\" cy=\"{:.1}\" r=\"{radius}\" fill=\"{}\"/>",
                        center.x,
                        center.y,
                        fill.hex()
                    );
                }
                Shape::Text {
                    at,
                    scale,
                    color,
                    anchor,
                    text,
                } => {
                    let anchor = match anchor {
                        Anchor::Start => "start",
                        Anchor::Middle => "middle",
                        Anchor::End => "end",
                    };
                    // A monospace face whose advance (0.6 em) is the PNG font's cell.
                    let size = Self::CHAR_WIDTH * *scale as f64 / 0.6;
                    let _ = writeln!(
                        s,
                        "<text x=\"{:.1}\" y=\"{:.1}\" font-family=\"DejaVu Sans Mono, Menlo, Consolas, monospace\" font-size=\"{size:.1}\" fill=\"{}\" text-anchor=\"{anchor}\" dominant-baseline=\"central\" xml:space=\"preserve\">{}</text>",
                        at.x,
                        at.y,
                        color.hex(),
                        xml_escape(text)
                    );
                }
            }
        }
        s.push_str("</svg>\n");
        s
    }

    /// The picture as 8-bit RGB pixels, row by row from the top.
    pub fn to_rgb(&self) -> Vec<u8> {
        let (w, h) = (self.width.min(MAX_SIDE) as usize, self.height.min(MAX_SIDE) as usize);
        let ss = (MAX_SAMPLES / w.max(h).max(1)).clamp(1, SUPERSAMPLE);
        let mut r = Raster::new(w * ss, h * ss, self.background);
        let k = ss as f64;
        for shape in &self.shapes {
            match shape {
                Shape::Polygon { points, fill, stroke } => {
                    let pts: Vec<DVec2> = points.iter().map(|&p| p * k).collect();
                    r.fill_polygon(&pts, *fill);
                    if let Some((c, width)) = stroke {
                        for (i, &a) in pts.iter().enumerate() {
                            r.line(a, pts[(i + 1) % pts.len()], width * k, *c);
                        }
                    }
                }
                Shape::Line { from, to, color, width } => r.line(*from * k, *to * k, width * k, *color),
                Shape::Dot { center, radius, fill } => r.disc(*center * k, radius * k, *fill),
                Shape::Text {
                    at,
                    scale,
                    color,
                    anchor,
                    text,
                } => {
                    let width = Self::char_width(text, *scale);
                    let x0 = match anchor {
                        Anchor::Start => at.x,
                        Anchor::Middle => at.x - width / 2.0,
                        Anchor::End => at.x - width,
                    };
                    // Whole output pixels: crisp glyphs.
                    let origin = DVec2::new(x0.round(), (at.y - 4.0 * *scale as f64).round()) * k;
                    r.text(origin, (*scale).min(64) as usize * ss, text, *color);
                }
            }
        }
        r.downsample(ss)
    }

    /// The picture as a PNG file.
    pub fn to_png(&self) -> std::io::Result<Vec<u8>> {
        let pixels = self.to_rgb();
        let mut out = Vec::new();
        let mut enc = png::Encoder::new(&mut out, self.width.min(MAX_SIDE), self.height.min(MAX_SIDE));
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::High);
        let mut writer = enc.write_header().map_err(std::io::Error::other)?;
        writer.write_image_data(&pixels).map_err(std::io::Error::other)?;
        writer.finish().map_err(std::io::Error::other)?;
        Ok(out)
    }
}

fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            c if (c as u32) < 0x20 => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// An RGB sample buffer.
struct Raster {
    w: usize,
    h: usize,
    px: Vec<[u8; 3]>,
}

impl Raster {
    fn new(w: usize, h: usize, bg: Rgb) -> Self {
        Raster {
            w,
            h,
            px: vec![[bg.0, bg.1, bg.2]; w * h],
        }
    }

    /// Paints samples `x0..x1` of row `y` (clipped).
    fn span(&mut self, y: i64, x0: i64, x1: i64, c: Rgb) {
        if y < 0 || y >= self.h as i64 {
            return;
        }
        let (x0, x1) = (x0.max(0), x1.min(self.w as i64));
        if x0 >= x1 {
            return;
        }
        let row = y as usize * self.w;
        self.px[row + x0 as usize..row + x1 as usize].fill([c.0, c.1, c.2]);
    }

    /// Rows whose sample centres (y + 0.5) lie in `lo..hi`, clipped.
    fn rows(&self, lo: f64, hi: f64) -> std::ops::Range<i64> {
        let first = (lo - 0.5).ceil().max(0.0);
        let last = (hi - 0.5).ceil().min(self.h as f64);
        if first.is_nan() || last.is_nan() || first >= last {
            return 0..0;
        }
        first as i64..last as i64
    }

    /// Even-odd scanline fill: samples whose centres are inside.
    fn fill_polygon(&mut self, pts: &[DVec2], c: Rgb) {
        if pts.len() < 3 || pts.iter().any(|p| !p.is_finite()) {
            return;
        }
        let (lo, hi) = pts
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), p| (l.min(p.y), h.max(p.y)));
        let mut xs = Vec::with_capacity(pts.len());
        for y in self.rows(lo, hi) {
            let yc = y as f64 + 0.5;
            xs.clear();
            for (i, &a) in pts.iter().enumerate() {
                let b = pts[(i + 1) % pts.len()];
                if (a.y <= yc) != (b.y <= yc) {
                    xs.push(a.x + (yc - a.y) * (b.x - a.x) / (b.y - a.y));
                }
            }
            xs.sort_by(f64::total_cmp);
            for pair in xs.chunks_exact(2) {
                let x0 = (pair[0] - 0.5).ceil().clamp(-1.0, self.w as f64 + 1.0) as i64;
                let x1 = (pair[1] - 0.5).ceil().clamp(-1.0, self.w as f64 + 1.0) as i64;
                self.span(y, x0, x1, c);
            }
        }
    }

    fn disc(&mut self, center: DVec2, radius: f64, c: Rgb) {
        if !center.is_finite() || !radius.is_finite() || radius <= 0.0 {
            return;
        }
        let r = radius.max(0.75);
        for y in self.rows(center.y - r, center.y + r) {
            let dy = y as f64 + 0.5 - center.y;
            let half = (r * r - dy * dy).max(0.0).sqrt();
            let x0 = (center.x - half - 0.5).ceil().clamp(-1.0, self.w as f64 + 1.0) as i64;
            let x1 = (center.x + half - 0.5).ceil().clamp(-1.0, self.w as f64 + 1.0) as i64;
            self.span(y, x0, x1, c);
        }
    }

    /// A line of at least one sample's width, with round ends.
    fn line(&mut self, a: DVec2, b: DVec2, width: f64, c: Rgb) {
        let half = width.max(1.0) / 2.0;
        let d = b - a;
        let len = d.length();
        if len > 0.0 {
            let n = DVec2::new(-d.y, d.x) / len * half;
            self.fill_polygon(&[a + n, b + n, b - n, a - n], c);
        }
        if half > 0.75 {
            self.disc(a, half, c);
            self.disc(b, half, c);
        }
    }

    /// Text with its top-left corner at `origin`, each font pixel `k` samples.
    fn text(&mut self, origin: DVec2, k: usize, text: &str, c: Rgb) {
        let limit = (self.w + self.h) as f64;
        if !(origin.x.abs() < limit && origin.y.abs() < limit) {
            return;
        }
        let (x0, y0) = (origin.x as i64, origin.y as i64);
        for (i, ch) in text.chars().enumerate().take(self.w) {
            let code = if (' '..='~').contains(&ch) { ch } else { '?' };
            let glyph = font::ASCII[code as usize - 32];
            for (row, bits) in glyph.iter().enumerate() {
                for col in 0..8 {
                    if bits >> col & 1 == 1 {
                        let x = x0 + ((i * 8 + col) * k) as i64;
                        let y = y0 + (row * k) as i64;
                        for yy in y..y + k as i64 {
                            self.span(yy, x, x + k as i64, c);
                        }
                    }
                }
            }
        }
    }

    /// Averages `k` × `k` blocks of samples into pixels.
    fn downsample(&self, k: usize) -> Vec<u8> {
        let (w, h) = (self.w / k, self.h / k);
        let mut out = Vec::with_capacity(w * h * 3);
        let n = (k * k) as u32;
        for y in 0..h {
            for x in 0..w {
                let mut sum = [0u32; 3];
                for dy in 0..k {
                    let row = (y * k + dy) * self.w + x * k;
                    for p in &self.px[row..row + k] {
                        for (s, &v) in sum.iter_mut().zip(p) {
                            *s += v as u32;
                        }
                    }
                }
                out.extend(sum.map(|s| ((s + n / 2) / n) as u8));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pixel(c: &Canvas, x: u32, y: u32) -> [u8; 3] {
        let rgb = c.to_rgb();
        let i = ((y * c.width + x) * 3) as usize;
        [rgb[i], rgb[i + 1], rgb[i + 2]]
    }

    #[test]
    fn shapes_are_painted_in_order() {
        let mut c = Canvas::new(20, 10, Rgb::WHITE);
        c.push(Shape::Polygon {
            points: vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(10.0, 0.0),
                DVec2::new(10.0, 10.0),
                DVec2::new(0.0, 10.0),
            ],
            fill: Rgb(255, 0, 0),
            stroke: None,
        });
        c.push(Shape::Dot {
            center: DVec2::new(5.0, 5.0),
            radius: 2.0,
            fill: Rgb(0, 0, 255),
        });
        assert_eq!(pixel(&c, 2, 8), [255, 0, 0]);
        assert_eq!(pixel(&c, 5, 5), [0, 0, 255]);
        assert_eq!(pixel(&c, 15, 5), [255, 255, 255]);
        // Half-covered pixels blend.
        let mut c = Canvas::new(4, 4, Rgb::WHITE);
        c.push(Shape::Polygon {
            points: vec![
                DVec2::new(0.0, 0.0),
                DVec2::new(1.5, 0.0),
                DVec2::new(1.5, 4.0),
                DVec2::new(0.0, 4.0),
            ],
            fill: Rgb::BLACK,
            stroke: None,
        });
        let p = pixel(&c, 1, 1)[0];
        assert!(p > 40 && p < 215, "{p}");
    }

    #[test]
    fn text_and_png_are_produced() {
        let mut c = Canvas::new(64, 16, Rgb::WHITE);
        c.push(Shape::Text {
            at: DVec2::new(32.0, 8.0),
            scale: 1,
            color: Rgb::BLACK,
            anchor: Anchor::Middle,
            text: "A<b>é".into(),
        });
        let svg = c.to_svg();
        assert!(svg.contains("A&lt;b&gt;é") && svg.ends_with("</svg>\n"));
        assert!(c.to_rgb().contains(&0));
        let png = c.to_png().unwrap();
        assert_eq!(&png[1..4], b"PNG");
    }

    #[test]
    fn degenerate_shapes_do_not_panic() {
        let mut c = Canvas::new(8, 8, Rgb::WHITE);
        let nan = DVec2::splat(f64::NAN);
        let big = DVec2::splat(1e300);
        c.push(Shape::Polygon {
            points: vec![nan, big, -big],
            fill: Rgb::BLACK,
            stroke: Some((Rgb::BLACK, 1.0)),
        });
        c.push(Shape::Line {
            from: big,
            to: -big,
            color: Rgb::BLACK,
            width: f64::INFINITY,
        });
        c.push(Shape::Dot {
            center: DVec2::ZERO,
            radius: 1e300,
            fill: Rgb::BLACK,
        });
        c.push(Shape::Text {
            at: big,
            scale: 3,
            color: Rgb::BLACK,
            anchor: Anchor::End,
            text: "x".into(),
        });
        let _ = c.to_rgb();
        let _ = Canvas::new(0, 0, Rgb::WHITE).to_png();
    }
}
