//! Frames shown without a WebGPU canvas. A browser that composites the
//! page in software cannot back a WebGPU canvas's frames (headless Chromium
//! without a GPU: its GPU process fails to make the canvas's shared image
//! and destroys the device, "Device was destroyed"; reproduced in plain
//! JavaScript, without hikari). There the page draws each frame into a
//! texture, reads it back and puts it into a 2D canvas laid over winit's,
//! which still takes the input (the copy lets pointer events through).

use crate::page;
use wasm_bindgen::{Clamped, JsCast};
use web_sys::{CanvasRenderingContext2d, HtmlCanvasElement, ImageData};

/// What the page says about the copy (in the panel's adapter line).
pub const NOTE: &str = "shown through a 2D canvas: this browser cannot present a WebGPU one";

pub struct CanvasCopy {
    canvas: HtmlCanvasElement,
    context: CanvasRenderingContext2d,
    /// What each frame is drawn into, of the canvas's size.
    pub target: wgpu::Texture,
}

impl CanvasCopy {
    /// The targets' format: 8-bit sRGB, as the 2D canvas takes its pixels.
    pub const FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

    /// A 2D canvas over `under`, and a target of `width × height`.
    pub fn new(device: &wgpu::Device, under: &HtmlCanvasElement, width: u32, height: u32) -> Result<Self, String> {
        let document = page::document();
        let canvas: HtmlCanvasElement = document
            .create_element("canvas")
            .and_then(|e| e.dyn_into().map_err(|_| "not a canvas".into()))
            .map_err(|e| format!("cannot make a 2D canvas: {e:?}"))?;
        canvas.set_id("hikari-copy");
        // Over winit's canvas, which fills the page, taking no input.
        let style = canvas.style();
        for (name, value) in [
            ("position", "fixed"),
            ("left", "0"),
            ("top", "0"),
            ("width", "100vw"),
            ("height", "100vh"),
            ("pointer-events", "none"),
        ] {
            style.set_property(name, value).map_err(|e| format!("cannot place the 2D canvas: {e:?}"))?;
        }
        under.after_with_node_1(&canvas).map_err(|e| format!("cannot add the 2D canvas to the page: {e:?}"))?;
        let context = canvas
            .get_context("2d")
            .ok()
            .flatten()
            .and_then(|c| c.dyn_into::<CanvasRenderingContext2d>().ok())
            .ok_or("the browser offers no 2D canvas either")?;
        let target = Self::make_target(device, width, height);
        let copy = CanvasCopy { canvas, context, target };
        copy.size_canvas();
        Ok(copy)
    }

    fn make_target(device: &wgpu::Device, width: u32, height: u32) -> wgpu::Texture {
        device.create_texture(&wgpu::TextureDescriptor {
            label: Some("canvas copy"),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: Self::FORMAT,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        })
    }

    fn size_canvas(&self) {
        self.canvas.set_width(self.target.width());
        self.canvas.set_height(self.target.height());
    }

    /// Frames of `width × height` from now on.
    pub fn resize(&mut self, device: &wgpu::Device, width: u32, height: u32) {
        self.target = Self::make_target(device, width, height);
        self.size_canvas();
    }

    /// Puts a frame read back from a target into the canvas; a frame of an
    /// older size (the page was resized meanwhile) is dropped.
    pub fn show(&self, width: u32, mut pixels: Vec<u8>) -> Result<(), String> {
        if width != self.target.width() || pixels.len() != (4 * width * self.target.height()) as usize {
            return Ok(());
        }
        // Opaque, whatever the present pass left in alpha (the canvas
        // would blend the frame with the page).
        pixels.iter_mut().skip(3).step_by(4).for_each(|a| *a = 255);
        let image = ImageData::new_with_u8_clamped_array_and_sh(Clamped(&pixels), width, self.target.height())
            .map_err(|e| format!("cannot make the frame's image: {e:?}"))?;
        self.context.put_image_data(&image, 0.0, 0.0).map_err(|e| format!("cannot draw the frame: {e:?}"))
    }
}

impl Drop for CanvasCopy {
    fn drop(&mut self) {
        self.canvas.remove();
    }
}
