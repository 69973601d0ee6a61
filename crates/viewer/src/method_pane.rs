//! The method's pane, painted inside egui's pass by a paint callback: the frame's linear
//! image tone-mapped on the GPU straight into the window
//! ([`mirrorbox_raster::display_tone_map`]): no readback, no texture of its own, no pass of
//! its own.

use mirrorbox_raster::display_tone_map::{DisplayToneMap, ToneMapSource, ToneMapUniform};
use std::sync::Arc;

/// One frame's paint of the method pane.
pub struct MethodPanePaint {
    pub tone_map: Arc<DisplayToneMap>,
    pub source: Arc<ToneMapSource>,
    pub uniform: ToneMapUniform,
}

impl egui_wgpu::CallbackTrait for MethodPanePaint {
    fn prepare(
        &self,
        _device: &wgpu::Device,
        queue: &wgpu::Queue,
        _screen: &egui_wgpu::ScreenDescriptor,
        _encoder: &mut wgpu::CommandEncoder,
        _resources: &mut egui_wgpu::CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        self.source.set(queue, self.uniform);
        Vec::new()
    }

    fn paint(
        &self,
        _info: egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        _resources: &egui_wgpu::CallbackResources,
    ) {
        // egui set the viewport to the pane's rectangle and the scissor to its clip.
        self.tone_map.draw(pass, &self.source);
    }
}
