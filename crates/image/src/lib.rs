//! Images of mirrorbox: linear RGB float images, the contract's sRGB output, and files.
//!
//! Linear radiance is stored as EXR (float32 RGB, with provenance in the header); what a
//! person looks at is an 8-bit sRGB PNG made with [`srgb`]'s exposure + transfer function,
//! the tone mapping that `docs/shading.md` fixes. Every write goes to a temporary file in
//! the destination folder and is renamed into place, so a failed or interrupted write never
//! leaves a half-written output behind.

pub mod colormap;
pub mod metrics;
pub mod srgb;
pub mod stereo;

pub use mirrorbox_files::StagedFiles;
use std::path::{Path, PathBuf};

/// A linear RGB image, row-major, top row first (the project's pixel convention).
#[derive(Clone, Debug, PartialEq)]
pub struct RgbImage {
    pub width: u32,
    pub height: u32,
    pub pixels: Vec<[f32; 3]>,
}

impl RgbImage {
    pub fn new(width: u32, height: u32) -> Self {
        RgbImage {
            width,
            height,
            pixels: vec![[0.0; 3]; width as usize * height as usize],
        }
    }

    pub fn from_fn(width: u32, height: u32, f: impl Fn(u32, u32) -> [f32; 3]) -> Self {
        let pixels = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| f(x, y))
            .collect();
        RgbImage {
            width,
            height,
            pixels,
        }
    }

    pub fn get(&self, x: u32, y: u32) -> [f32; 3] {
        self.pixels[(y * self.width + x) as usize]
    }

    /// Why this is no picture of radiance, if it is not: the first pixel (row-major) that is
    /// NaN, infinite or negative. Metrics of such an image are NaN (records `null`), and a NaN
    /// hides in `max |d|`, so `compare` and `score` refuse it with this message.
    pub fn radiance_problem(&self) -> Option<String> {
        let w = self.width.max(1) as usize;
        self.pixels
            .iter()
            .enumerate()
            .find(|(_, p)| p.iter().any(|c| !c.is_finite() || *c < 0.0))
            .map(|(i, p)| {
                format!(
                    "pixel ({}, {}) is {p:?}: radiance is finite and ≥ 0",
                    i % w,
                    i / w
                )
            })
    }

    /// 8-bit sRGB bytes (RGB, row-major) after the contract's tone mapping.
    pub fn to_srgb8(&self, exposure: f32) -> Vec<u8> {
        self.pixels
            .iter()
            .flat_map(|p| p.map(|c| srgb::encode8(c * exposure)))
            .collect()
    }
}

#[derive(Debug, thiserror::Error)]
pub enum ImageError {
    #[error("{path}: {message}")]
    Io { path: PathBuf, message: String },
    #[error("{path}: unsupported image type (expected .exr or .png)")]
    UnsupportedType { path: PathBuf },
}

fn io_error(path: &Path, message: impl ToString) -> ImageError {
    ImageError::Io {
        path: path.to_path_buf(),
        message: message.to_string(),
    }
}

/// Runs `write` on a temporary path beside `path`, then renames it into place — at once
/// ([`mirrorbox_files::write_atomically_with`]), or with the other outputs of a command when
/// `staged` is given ([`StagedFiles`]). `path` is never left half-written.
fn put(
    path: &Path,
    staged: Option<&mut StagedFiles>,
    write: impl FnOnce(&Path) -> Result<(), String>,
) -> Result<(), ImageError> {
    match staged {
        None => mirrorbox_files::write_atomically_with(path, write),
        Some(staged) => staged.stage_with(path, write),
    }
    .map_err(|e| io_error(&e.path, e.message))
}

/// Writes the contract's tone-mapped sRGB image as an 8-bit PNG.
pub fn write_png(path: &Path, image: &RgbImage, exposure: f32) -> Result<(), ImageError> {
    write_png_bytes(path, image.width, image.height, &image.to_srgb8(exposure))
}

/// [`write_png`], staged with the other outputs of a command.
pub fn stage_png(
    staged: &mut StagedFiles,
    path: &Path,
    image: &RgbImage,
    exposure: f32,
) -> Result<(), ImageError> {
    png(
        path,
        Some(staged),
        image.width,
        image.height,
        &image.to_srgb8(exposure),
    )
}

/// Writes 8-bit sRGB bytes (RGB, row-major) as a PNG.
pub fn write_png_bytes(
    path: &Path,
    width: u32,
    height: u32,
    bytes: &[u8],
) -> Result<(), ImageError> {
    png(path, None, width, height, bytes)
}

/// [`write_png_bytes`], staged with the other outputs of a command.
pub fn stage_png_bytes(
    staged: &mut StagedFiles,
    path: &Path,
    width: u32,
    height: u32,
    bytes: &[u8],
) -> Result<(), ImageError> {
    png(path, Some(staged), width, height, bytes)
}

fn png(
    path: &Path,
    staged: Option<&mut StagedFiles>,
    width: u32,
    height: u32,
    bytes: &[u8],
) -> Result<(), ImageError> {
    put(path, staged, |tmp| {
        image::save_buffer_with_format(
            tmp,
            bytes,
            width,
            height,
            image::ColorType::Rgb8,
            image::ImageFormat::Png,
        )
        .map_err(|e| e.to_string())
    })
}

/// Writes linear float32 RGB EXR with `attributes` as text attributes in the header
/// (provenance: scene hash, spp, depth, time, ...).
pub fn write_exr(
    path: &Path,
    image: &RgbImage,
    attributes: &[(&str, String)],
) -> Result<(), ImageError> {
    exr_file(path, None, image, attributes)
}

/// [`write_exr`], staged with the other outputs of a command.
pub fn stage_exr(
    staged: &mut StagedFiles,
    path: &Path,
    image: &RgbImage,
    attributes: &[(&str, String)],
) -> Result<(), ImageError> {
    exr_file(path, Some(staged), image, attributes)
}

fn exr_file(
    path: &Path,
    staged: Option<&mut StagedFiles>,
    image: &RgbImage,
    attributes: &[(&str, String)],
) -> Result<(), ImageError> {
    use exr::prelude::*;
    let mut text = Vec::with_capacity(attributes.len());
    for (key, value) in attributes {
        let k = Text::new_or_none(key)
            .ok_or_else(|| io_error(path, format!("header key {key:?} is not ASCII")))?;
        let v = Text::new_or_none(value)
            .ok_or_else(|| io_error(path, format!("header value {value:?} is not ASCII")))?;
        text.push((k, AttributeValue::Text(v)));
    }
    let channels = SpecificChannels::rgb(|Vec2(x, y): Vec2<usize>| {
        let p = image.pixels[y * image.width as usize + x];
        (p[0], p[1], p[2])
    });
    let mut exr_image =
        Image::from_channels((image.width as usize, image.height as usize), channels);
    exr_image.attributes.other.extend(text);
    put(path, staged, |tmp| {
        exr_image.write().to_file(tmp).map_err(|e| e.to_string())
    })
}

/// The text attributes of an EXR header (the ones [`write_exr`] stores).
pub fn read_exr_attributes(path: &Path) -> Result<Vec<(String, String)>, ImageError> {
    // A regular file of a bounded size, opened without blocking (a FIFO named as an image
    // had blocked `compare` here, before `read_image`'s own check).
    let file = mirrorbox_files::open_regular(path, MAX_IMAGE_FILE_BYTES, "image file")
        .map_err(|e| io_error(path, e.message))?;
    let meta = exr::meta::MetaData::read_from_buffered(std::io::BufReader::new(file), false)
        .map_err(|e| io_error(path, e))?;
    let mut out: Vec<(String, String)> = meta
        .headers
        .iter()
        .flat_map(|h| {
            h.shared_attributes
                .other
                .iter()
                .chain(h.own_attributes.other.iter())
        })
        .filter_map(|(k, v)| match v {
            exr::meta::attribute::AttributeValue::Text(t) => Some((k.to_string(), t.to_string())),
            _ => None,
        })
        .collect();
    out.sort();
    Ok(out)
}

/// Reads an image as linear RGB: EXR as stored; PNG decoded through the inverse sRGB
/// transfer (no exposure is undone).
pub fn read_image(path: &Path) -> Result<RgbImage, ImageError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    if !matches!(ext.as_deref(), Some("exr" | "png")) {
        return Err(ImageError::UnsupportedType {
            path: path.to_path_buf(),
        });
    }
    // A regular file of bounded size (no FIFO that blocks, no device that never ends).
    mirrorbox_files::open_regular(path, MAX_IMAGE_FILE_BYTES, "image file")
        .map_err(|e| io_error(path, e.message))?;
    if ext.as_deref() == Some("exr") {
        read_exr(path)
    } else {
        // The header first: the size it claims is checked before the pixels are decoded (a
        // PNG of a few hundred KB may declare 16384² pixels of gigabytes).
        let (width, height) = png_size(path)?;
        check_size(path, width, height)?;
        let mut reader = image::ImageReader::open(path).map_err(|e| io_error(path, e))?;
        let mut limits = image::Limits::default();
        limits.max_image_width = Some(MAX_IMAGE_SIDE);
        limits.max_image_height = Some(MAX_IMAGE_SIDE);
        limits.max_alloc = Some(MAX_PIXELS * 16);
        reader.limits(limits);
        let decoded = reader.decode().map_err(|e| decode_error(path, e))?;
        check_size(path, decoded.width(), decoded.height())?;
        // 8-bit only (grey or colour, alpha ignored): a 16-bit PNG had been cut to 8 bits
        // without a word.
        use image::ColorType;
        if !matches!(
            decoded.color(),
            ColorType::Rgb8 | ColorType::Rgba8 | ColorType::L8 | ColorType::La8
        ) {
            return Err(io_error(
                path,
                format!(
                    "a PNG is read as 8 bits a channel, sRGB-encoded (RGB, RGBA or grey; alpha \
                     ignored); this one is {:?}",
                    decoded.color()
                ),
            ));
        }
        let img = decoded.to_rgb8();
        let (w, h) = img.dimensions();
        let pixels = img.pixels().map(|p| p.0.map(srgb::decode8)).collect();
        Ok(RgbImage {
            width: w,
            height: h,
            pixels,
        })
    }
}

/// The size an EXR or PNG declares in its header, read without decoding a pixel: a caller
/// that knows the size it wants (a view's) compares it before [`read_image`] decodes.
pub fn image_size(path: &Path) -> Result<(u32, u32), ImageError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    mirrorbox_files::open_regular(path, MAX_IMAGE_FILE_BYTES, "image file")
        .map_err(|e| io_error(path, e.message))?;
    match ext.as_deref() {
        Some("exr") => exr_size(path),
        Some("png") => png_size(path),
        _ => Err(ImageError::UnsupportedType {
            path: path.to_path_buf(),
        }),
    }
}

fn png_size(path: &Path) -> Result<(u32, u32), ImageError> {
    image::ImageReader::open(path)
        .map_err(|e| io_error(path, e))?
        .into_dimensions()
        .map_err(|e| decode_error(path, e))
}

/// What a file's first bytes say it is, where they say so: the signatures of the formats a
/// renderer is likely to write (OpenEXR, PNG, JPEG, Radiance HDR, TIFF).
fn sniffed_format(path: &Path) -> Option<&'static str> {
    use std::io::Read as _;
    let mut head = [0u8; 8];
    let file = mirrorbox_files::open_regular(path, MAX_IMAGE_FILE_BYTES, "image file").ok()?;
    let n = file.take(8).read(&mut head).ok()?;
    let head = &head[..n];
    [
        (&b"\x76\x2f\x31\x01"[..], "an OpenEXR file"),
        (&b"\x89PNG\r\n\x1a\n"[..], "a PNG file"),
        (&b"\xff\xd8\xff"[..], "a JPEG file"),
        (&b"#?RADIAN"[..], "a Radiance HDR file"),
        (&b"#?RGBE"[..], "a Radiance HDR file"),
        (&b"II*\0"[..], "a TIFF file"),
        (&b"MM\0*"[..], "a TIFF file"),
    ]
    .into_iter()
    .find(|(magic, _)| head.starts_with(magic))
    .map(|(_, what)| what)
}

/// A decoder's refusal of `path`, said in what the file is where its first bytes show it is
/// of another format than its extension (a PNG saved as `camera.exr`: the EXR crate's words
/// had been "file identifier missing").
fn decode_error(path: &Path, e: impl ToString) -> ImageError {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    let named = match ext.as_deref() {
        Some("exr") => "an OpenEXR file",
        Some("png") => "a PNG file",
        _ => "",
    };
    match sniffed_format(path) {
        Some(what) if what != named => io_error(
            path,
            format!(
                "is {what} by its first bytes, not what its extension says ({}); an image is \
                 read as .exr (linear radiance) or .png (8-bit sRGB), named after its format",
                ext.as_deref().unwrap_or("none")
            ),
        ),
        _ => io_error(path, e),
    }
}

/// The first layer's size (the one [`read_image`] reads); every layer's is checked against
/// the limits.
fn exr_size(path: &Path) -> Result<(u32, u32), ImageError> {
    sized(path, &exr_meta(path)?)
}

/// An EXR's header, read once for its size and its channels' sample types.
fn exr_meta(path: &Path) -> Result<exr::meta::MetaData, ImageError> {
    exr::meta::MetaData::read_from_file(path, false).map_err(|e| decode_error(path, e))
}

/// [`exr_size`] of a header read.
fn sized(path: &Path, meta: &exr::meta::MetaData) -> Result<(u32, u32), ImageError> {
    let mut first = None;
    for header in &meta.headers {
        let size = header.layer_size;
        let (w, h) = (
            u32::try_from(size.width()).unwrap_or(u32::MAX),
            u32::try_from(size.height()).unwrap_or(u32::MAX),
        );
        check_size(path, w, h)?;
        first.get_or_insert((w, h));
    }
    first.ok_or_else(|| io_error(path, "an EXR without a layer"))
}

/// Largest image file read (an 8192² float RGBA EXR, uncompressed, is 1.07 GB).
pub const MAX_IMAGE_FILE_BYTES: u64 = 3 << 29;
/// Largest image side read; the scene's limit (`mirrorbox_scene::limits::MAX_IMAGE_SIDE`).
pub const MAX_IMAGE_SIDE: u32 = 16384;
/// Most pixels in an image read; the scene's limit (`mirrorbox_scene::limits::MAX_PIXELS`).
pub const MAX_PIXELS: u64 = 1 << 26;

/// Refuses an image beyond the sizes mirrorbox writes, before its pixels are allocated.
fn check_size(path: &Path, width: u32, height: u32) -> Result<(), ImageError> {
    let pixels = u64::from(width) * u64::from(height);
    if width.max(height) > MAX_IMAGE_SIDE || pixels > MAX_PIXELS || pixels == 0 {
        return Err(io_error(
            path,
            format!(
                "a {width}×{height} image; images of 1..{MAX_IMAGE_SIDE} pixels per side and at most {MAX_PIXELS} pixels are read"
            ),
        ));
    }
    Ok(())
}

/// The sample type of an EXR's R, G and B channels (its first layer): `"float"`, or `"half"`
/// where any is half. Unsigned-integer channels are refused (read as floats they had been
/// scored as radiance), and so is a first layer without channels named R, G and B.
pub fn exr_rgb_samples(path: &Path) -> Result<&'static str, ImageError> {
    rgb_samples(path, &exr_meta(path)?)
}

/// [`exr_rgb_samples`] of a header read.
fn rgb_samples(path: &Path, meta: &exr::meta::MetaData) -> Result<&'static str, ImageError> {
    use exr::meta::attribute::SampleType;
    let header = meta
        .headers
        .first()
        .ok_or_else(|| io_error(path, "an EXR without a layer"))?;
    let mut half = false;
    for channel in &header.channels.list {
        let name = channel.name.to_string();
        let base = name.rsplit('.').next().unwrap_or(&name);
        if !["R", "G", "B"].contains(&base) {
            continue;
        }
        match channel.sample_type {
            SampleType::U32 => {
                return Err(io_error(
                    path,
                    format!(
                        "channel {name} holds unsigned integers; an EXR's R, G and B are read \
                         as float or half (linear radiance)"
                    ),
                ));
            }
            SampleType::F16 => half = true,
            SampleType::F32 => {}
        }
    }
    // Channels named `R`, `G` and `B` themselves: a luminance-only file, or one whose
    // channels carry a layer's prefix (Blender's `View Layer.Combined.R`), which the reader
    // does not take for them, is refused naming the channels it has.
    let names: Vec<String> = header
        .channels
        .list
        .iter()
        .map(|c| c.name.to_string())
        .collect();
    if !["R", "G", "B"].iter().all(|c| names.iter().any(|n| n == c)) {
        let prefixed = ["R", "G", "B"]
            .iter()
            .all(|c| names.iter().any(|n| n.ends_with(&format!(".{c}"))));
        let shown: Vec<&str> = names.iter().take(8).map(String::as_str).collect();
        return Err(io_error(
            path,
            format!(
                "an EXR's channels R, G and B are read (float or half; A ignored), from its \
                 first layer (part), which has {}{}{}",
                if shown.is_empty() {
                    "none".to_string()
                } else {
                    shown.join(", ")
                },
                if names.len() > shown.len() {
                    ", …"
                } else {
                    ""
                },
                if prefixed {
                    ": write them without the layer's prefix, as R, G and B"
                } else {
                    ""
                }
            ),
        ));
    }
    Ok(if half { "half" } else { "float" })
}

fn read_exr(path: &Path) -> Result<RgbImage, ImageError> {
    use exr::prelude::*;
    // The header first: the size it claims is checked before any pixel is allocated.
    let meta = exr_meta(path)?;
    sized(path, &meta)?;
    rgb_samples(path, &meta)?;
    let image = read_first_rgba_layer_from_file(
        path,
        |size, _| RgbImage::new(size.width() as u32, size.height() as u32),
        |img: &mut RgbImage, pos, (r, g, b, _a): (f32, f32, f32, f32)| {
            let w = img.width as usize;
            img.pixels[pos.y() * w + pos.x()] = [r, g, b];
        },
    )
    .map_err(|e| io_error(path, e))?;
    Ok(image.layer_data.channel_data.pixels)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gradient() -> RgbImage {
        RgbImage::from_fn(7, 5, |x, y| [x as f32 * 0.25, y as f32 * 0.5, 3.5])
    }

    /// An EXR without R, G and B (here luminance only) is refused saying what is read, not
    /// with the EXR crate's "no layer … matched your specified requirements".
    #[test]
    fn an_exr_without_rgb_says_what_is_read() {
        use exr::prelude::*;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("y.exr");
        let y = AnyChannel::new("Y", FlatSamples::F32(vec![0.5; 4 * 3]));
        Image::from_channels((4, 3), AnyChannels::sort(SmallVec::from_vec(vec![y])))
            .write()
            .to_file(&path)
            .unwrap();
        let e = read_image(&path).unwrap_err().to_string();
        assert!(
            e.contains("y.exr") && e.contains("channels R, G and B") && e.contains("has Y"),
            "{e}"
        );
    }

    /// An EXR whose channels carry a layer's prefix (as Blender writes them) is refused
    /// naming its channels and what to do, not "has none".
    #[test]
    fn an_exr_with_prefixed_channels_names_them() {
        use exr::prelude::*;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("blender.exr");
        let channel = |c: &str| {
            AnyChannel::new(
                Text::new_or_panic(format!("View Layer.Combined.{c}").as_str()),
                FlatSamples::F32(vec![0.5; 12]),
            )
        };
        Image::from_channels(
            (4, 3),
            AnyChannels::sort(SmallVec::from_vec(vec![
                channel("R"),
                channel("G"),
                channel("B"),
            ])),
        )
        .write()
        .to_file(&path)
        .unwrap();
        let e = read_image(&path).unwrap_err().to_string();
        assert!(
            e.contains("View Layer.Combined.R") && e.contains("without the layer's prefix"),
            "{e}"
        );
    }

    /// A file of one format named as the other is said to be so, by its first bytes.
    #[test]
    fn a_file_named_as_another_format_is_said_so() {
        let dir = tempfile::tempdir().unwrap();
        let png = dir.path().join("a.png");
        let exr = dir.path().join("a.exr");
        write_png(&png, &gradient(), 1.0).unwrap();
        write_exr(&exr, &gradient(), &[]).unwrap();
        let (png_as_exr, exr_as_png) = (dir.path().join("p.exr"), dir.path().join("e.png"));
        std::fs::copy(&png, &png_as_exr).unwrap();
        std::fs::copy(&exr, &exr_as_png).unwrap();
        for (path, what) in [
            (&png_as_exr, "a PNG file"),
            (&exr_as_png, "an OpenEXR file"),
        ] {
            for e in [
                read_image(path).unwrap_err().to_string(),
                image_size(path).unwrap_err().to_string(),
            ] {
                assert!(
                    e.contains(what) && e.contains("not what its extension says"),
                    "{e}"
                );
            }
        }
        // A file of its own format but broken keeps the decoder's words.
        std::fs::write(&png_as_exr, b"\x76\x2f\x31\x01 and then nothing").unwrap();
        let e = read_image(&png_as_exr).unwrap_err().to_string();
        assert!(!e.contains("not what its extension says"), "{e}");
    }

    #[test]
    fn exr_round_trip_is_exact_and_keeps_attributes() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.exr");
        let img = gradient();
        write_exr(&path, &img, &[("mirrorbox.spp", "16".into())]).unwrap();
        assert_eq!(read_image(&path).unwrap(), img);
        let attrs = read_exr_attributes(&path).unwrap();
        assert!(
            attrs.contains(&("mirrorbox.spp".into(), "16".into())),
            "{attrs:?}"
        );
        // Only the file itself is left in the folder: no temporary file.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    /// A PNG of a few bytes declaring more pixels than are read (16384 × 4097 > 2²⁶) is
    /// refused by its header, before its pixels are decoded: the decoder, reached first,
    /// allocated the declared image (a 783 KB file took 805 MB) and here fails on the missing
    /// data instead.
    #[test]
    fn a_png_is_refused_by_the_size_its_header_declares() {
        fn chunk(kind: &[u8; 4], data: &[u8]) -> Vec<u8> {
            let crc_of = |bytes: &[u8]| {
                let mut crc = !0u32;
                for &b in bytes {
                    crc ^= u32::from(b);
                    for _ in 0..8 {
                        crc = (crc >> 1) ^ (0xEDB8_8320 & (crc & 1).wrapping_neg());
                    }
                }
                !crc
            };
            let mut typed = kind.to_vec();
            typed.extend_from_slice(data);
            let mut out = (data.len() as u32).to_be_bytes().to_vec();
            out.extend_from_slice(&typed);
            out.extend_from_slice(&crc_of(&typed).to_be_bytes());
            out
        }
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("huge.png");
        let (w, h) = (
            MAX_IMAGE_SIDE,
            (MAX_PIXELS / u64::from(MAX_IMAGE_SIDE)) as u32 + 1,
        );
        let mut ihdr = w.to_be_bytes().to_vec();
        ihdr.extend_from_slice(&h.to_be_bytes());
        ihdr.extend_from_slice(&[8, 2, 0, 0, 0]); // 8-bit RGB
        let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
        png.extend(chunk(b"IHDR", &ihdr));
        png.extend(chunk(b"IDAT", &[0x78, 0x9c, 0x03, 0x00])); // far too little data
        png.extend(chunk(b"IEND", &[]));
        std::fs::write(&path, png).unwrap();
        assert_eq!(image_size(&path).unwrap(), (w, h));
        let e = read_image(&path).unwrap_err().to_string();
        assert!(e.contains(&format!("a {w}×{h} image")), "{e}");
    }

    #[test]
    fn png_round_trip_within_quantization() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.png");
        let img = RgbImage::from_fn(4, 3, |x, y| [x as f32 / 4.0, y as f32 / 3.0, 0.5]);
        write_png(&path, &img, 1.0).unwrap();
        let back = read_image(&path).unwrap();
        for (a, b) in img.pixels.iter().zip(&back.pixels) {
            for c in 0..3 {
                // One 8-bit sRGB step is at most ~0.0055 in linear near 1.
                assert!((a[c] - b[c]).abs() < 0.006, "{a:?} vs {b:?}");
            }
        }
    }
}
