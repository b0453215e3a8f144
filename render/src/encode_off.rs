//! The encoder of a build without the `video` feature (FFmpeg not linked): the renderer
//! still draws images (the Python package's ego camera, `ego`), but any video job fails
//! with [`NO_VIDEO`] — [`init`] refuses, so `Renderer::new` (which writes videos) does too.

use std::path::Path;

/// Why nothing can be encoded.
pub const NO_VIDEO: &str =
    "video encoding is not built in (rh-render without its `video` feature: FFmpeg is not linked)";

/// Refuses: there is no encoder in this build.
pub fn init() -> Result<(), String> {
    Err(NO_VIDEO.into())
}

/// No MP4 can be written in this build: the type has no values, and `create` refuses.
pub enum Mp4Writer {}

impl Mp4Writer {
    /// (Generic in the settings, so that this file names nothing of `encode`.)
    pub fn create<S>(
        _path: &Path,
        _width: u32,
        _height: u32,
        _fps: u32,
        _settings: &S,
    ) -> Result<Mp4Writer, String> {
        Err(NO_VIDEO.into())
    }

    pub fn push(&mut self, _rgba: &[u8]) -> Result<(), String> {
        match *self {}
    }

    pub fn finish(self) -> Result<u32, String> {
        match self {}
    }
}
