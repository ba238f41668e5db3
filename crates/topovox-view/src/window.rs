//! The interactive viewer (`topovox view`): a resizable window (winit,
//! X11) showing [`crate::gpu::Renderer`]'s frames, with an orbit and fly
//! camera and keys that switch each technique. The statistics (culling,
//! clusters kept, triangles, lights, light grid, CPU and GPU times) are
//! drawn over the picture (`text.wgsl`) and repeated in the window title.
//!
//! Controls: left drag orbits around the target, right drag pans, the
//! wheel zooms; W/A/S/D/Q/E fly (the target moves along); C cycles culling
//! none → frustum → occlusion → two-pass occlusion; Z toggles the Z-prepass; G gamma; L the
//! light-grid view (surfaces coloured by their cell's list length); R
//! resets the camera; B draws the cluster boxes (green drawn, red culled);
//! T hides the statistics overlay; Escape quits. The ray spray ([`crate::spray`]): P
//! (or the middle button) sprays rays in a narrow cone through the cursor,
//! each hit a point lit by its stored light term; M shows or hides the
//! mesh; X clears the points. The points are handed back on closing.
//!
//! Scripted (`frames`): after that many frames the viewer renders one more
//! frame off screen with the current camera and size, hands it to the
//! caller (a screenshot) and closes; CI runs this under Xvfb.

use std::sync::Arc;
use std::time::Instant;

use glam::Vec3;
use topovox::choice::Choice;
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::window::{Window, WindowId};

use crate::gpu::{Blit, Culling, Frame, FrameOptions, GpuScene, Renderer};
use crate::spray::{SprayOptions, SprayPoint, Tracer};
use crate::{Camera, Scene, ViewError};

/// How the viewer starts.
#[derive(Clone, Copy, Debug)]
pub struct ViewOptions {
    /// Initial window size in pixels.
    pub width: u32,
    /// Initial height.
    pub height: u32,
    /// Starting camera (`None`: framing the scene).
    pub camera: Option<Camera>,
    /// The up axis (0, 1, 2).
    pub up: usize,
    /// Culling to start with.
    pub culling: Culling,
    /// Z-prepass at start.
    pub prepass: bool,
    /// Gamma at start.
    pub gamma: bool,
    /// Close after this many frames, with a screenshot.
    pub frames: Option<u32>,
    /// Rays per spray at the cursor.
    pub spray_rays: usize,
    /// Half-angle of the spray's cone, in degrees.
    pub spray_degrees: f32,
}

/// What a viewer session did.
#[derive(Debug)]
pub struct ViewReport {
    /// Frames shown.
    pub frames: u32,
    /// The adapter.
    pub adapter: String,
    /// The last frame rendered off screen, in scripted runs.
    pub screenshot: Option<Frame>,
    /// The camera of that frame.
    pub camera: Camera,
    /// The spray's points: those given at start, then every spray's.
    pub points: Vec<SprayPoint>,
}

/// Orbit camera state: a target, a distance and two angles around `up`.
struct Orbit {
    target: Vec3,
    distance: f32,
    yaw: f32,
    pitch: f32,
    up: usize,
    fov_deg: f32,
}

impl Orbit {
    fn from_camera(c: &Camera, up: usize) -> Orbit {
        let d = c.eye - c.target;
        let (h0, h1) = ((up + 1) % 3, (up + 2) % 3);
        let distance = d.length().max(1e-6);
        Orbit {
            target: c.target,
            distance,
            yaw: d[h1].atan2(d[h0]),
            pitch: (d[up] / distance).clamp(-1.0, 1.0).asin(),
            up,
            fov_deg: c.fov_deg,
        }
    }

    fn camera(&self) -> Camera {
        let (h0, h1) = ((self.up + 1) % 3, (self.up + 2) % 3);
        let mut d = Vec3::ZERO;
        d[h0] = self.pitch.cos() * self.yaw.cos();
        d[h1] = self.pitch.cos() * self.yaw.sin();
        d[self.up] = self.pitch.sin();
        let mut up = Vec3::ZERO;
        up[self.up] = 1.0;
        Camera { eye: self.target + d * self.distance, target: self.target, up, fov_deg: self.fov_deg }
    }

    /// Forward and right directions of the current view.
    fn axes(&self) -> (Vec3, Vec3) {
        let c = self.camera();
        let fwd = (c.target - c.eye).normalize_or_zero();
        (fwd, fwd.cross(c.up).normalize_or_zero())
    }
}

struct Active {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    view_format: wgpu::TextureFormat,
    renderer: Renderer,
    uploaded: GpuScene,
    blit: Blit,
}

struct App {
    scene: Scene,
    /// Built at the first spray.
    tracer: Option<Tracer>,
    points: Vec<SprayPoint>,
    sprays: u64,
    mesh: bool,
    boxes: bool,
    text: bool,
    opts: ViewOptions,
    home: Camera,
    orbit: Orbit,
    culling: Culling,
    prepass: bool,
    gamma: bool,
    light_grid: bool,
    active: Option<Active>,
    frames: u32,
    drag: Option<(MouseButton, (f64, f64))>,
    cursor: (f64, f64),
    error: Option<ViewError>,
    screenshot: Option<(Frame, Camera)>,
    adapter: String,
}

/// Opens the window and runs until it is closed (or, scripted, until
/// `frames` frames were shown).
pub fn run(scene: Scene, points: Vec<SprayPoint>, opts: ViewOptions) -> Result<ViewReport, ViewError> {
    let (lo, hi) = scene.bounds().ok_or(ViewError::EmptyScene)?;
    let home = opts.camera.unwrap_or_else(|| Camera::framing(lo, hi, opts.up));
    let event_loop = EventLoop::new().map_err(|e| ViewError::Window(e.to_string()))?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App {
        scene,
        tracer: None,
        points,
        sprays: 0,
        mesh: true,
        boxes: false,
        text: true,
        opts,
        home,
        orbit: Orbit::from_camera(&home, opts.up),
        culling: opts.culling,
        prepass: opts.prepass,
        gamma: opts.gamma,
        light_grid: false,
        active: None,
        frames: 0,
        drag: None,
        cursor: (0.0, 0.0),
        error: None,
        screenshot: None,
        adapter: String::new(),
    };
    event_loop.run_app(&mut app).map_err(|e| ViewError::Window(e.to_string()))?;
    if let Some(e) = app.error {
        return Err(e);
    }
    let (screenshot, camera) = match app.screenshot {
        Some((f, c)) => (Some(f), c),
        None => (None, app.orbit.camera()),
    };
    Ok(ViewReport { frames: app.frames, adapter: app.adapter, screenshot, camera, points: app.points })
}

impl App {
    fn fail(&mut self, event_loop: &ActiveEventLoop, e: ViewError) {
        self.error.get_or_insert(e);
        event_loop.exit();
    }

    fn open(&mut self, event_loop: &ActiveEventLoop) -> Result<Active, ViewError> {
        let attrs = Window::default_attributes()
            .with_title("topovox view")
            .with_inner_size(PhysicalSize::new(self.opts.width.max(1), self.opts.height.max(1)));
        let window = Arc::new(event_loop.create_window(attrs).map_err(|e| ViewError::Window(e.to_string()))?);
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(event_loop.owned_display_handle())));
        let surface = instance.create_surface(window.clone()).map_err(|e| ViewError::Window(e.to_string()))?;
        let renderer = Renderer::open(&instance, Some(&surface))?;
        let size = window.inner_size();
        let mut config = surface
            .get_default_config(&renderer.dev.adapter, size.width.max(1), size.height.max(1))
            .ok_or_else(|| ViewError::Window("the adapter cannot present to this window".into()))?;
        // The frame is already gamma-corrected (or not, as asked): present
        // it through a non-sRGB view so the bytes are shown as they are.
        let view_format = config.format.remove_srgb_suffix();
        if view_format != config.format {
            config.view_formats = vec![view_format];
        }
        config.present_mode = wgpu::PresentMode::AutoVsync;
        surface.configure(&renderer.dev.device, &config);
        let mut uploaded = renderer.upload(&self.scene)?;
        renderer.add_points(&mut uploaded, &self.points)?;
        let blit = renderer.blit(view_format);
        self.adapter = renderer.adapter();
        Ok(Active { window, surface, config, view_format, renderer, uploaded, blit })
    }

    fn options(&self, width: u32, height: u32) -> FrameOptions {
        FrameOptions {
            width,
            height,
            camera: self.orbit.camera(),
            culling: self.culling,
            prepass: self.prepass,
            gamma: self.gamma,
            light_grid_view: self.light_grid,
            read_hiz: false,
            mesh: self.mesh,
            boxes: self.boxes,
        }
    }

    fn draw(&mut self, event_loop: &ActiveEventLoop) {
        let Some((w, h)) = self.active.as_ref().map(|a| (a.config.width, a.config.height)) else { return };
        let opts = self.options(w, h);
        let Some(a) = &mut self.active else { return };
        let texture = match a.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t) | wgpu::CurrentSurfaceTexture::Suboptimal(t) => t,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                a.surface.configure(&a.renderer.dev.device, &a.config);
                return;
            }
            _ => return,
        };
        let view = texture.texture.create_view(&wgpu::TextureViewDescriptor { format: Some(a.view_format), ..Default::default() });
        let t0 = Instant::now();
        let stats = match a.renderer.present(&a.uploaded, &opts, &a.blit, &view) {
            Ok(s) => s,
            Err(e) => return self.fail(event_loop, e),
        };
        a.renderer.present_texture(texture);
        self.frames += 1;
        let ms = t0.elapsed().as_secs_f64() * 1e3;
        let culling = self.culling.name();
        let kept = stats.clusters_after_occlusion.unwrap_or(stats.clusters_after_frustum);
        let onoff = |b: bool| if b { "on" } else { "off" };
        let (total, mean, max) = a.uploaded.grid.stats();
        let gpu = stats.gpu.map_or("GPU times: not offered by this adapter".to_string(), |t| {
            format!("GPU ms: cull {:.2}  depth {:.2}  Hi-Z {:.2}  shade {:.2}", t.cull_ms, t.depth_ms, t.hiz_ms, t.shade_ms)
        });
        // The statistics line of seed 002, shown on the next frame (the
        // overlay, T hides it) and in the title.
        let lines = vec![
            format!(
                "culling {culling} (C)  prepass {} (Z)  gamma {} (G)  mesh {} (M)  boxes {} (B)",
                onoff(self.prepass),
                onoff(self.gamma),
                onoff(self.mesh),
                onoff(self.boxes)
            ),
            format!(
                "clusters {}/{}/{}  triangles {}/{}  points {}",
                kept, stats.clusters_after_frustum, stats.clusters, stats.triangles_drawn, stats.triangles, stats.points_drawn
            ),
            format!("lights {}  light grid {total} indices, {mean:.2} per cell, max {max}", a.uploaded.lights.lights),
            format!("frame {ms:.1} ms  {gpu}"),
        ];
        a.window.set_title(&format!("topovox view | {} | {} | {}", lines[0], lines[1], lines[3]));
        a.renderer.set_overlay(&mut a.uploaded, if self.text { &lines } else { &[] });
        if self.opts.frames.is_some_and(|n| self.frames >= n) {
            // The screenshot is the frame as render --gpu draws it: no text.
            a.renderer.set_overlay(&mut a.uploaded, &[]);
            match a.renderer.render(&a.uploaded, &opts) {
                Ok(f) => self.screenshot = Some((f, opts.camera)),
                Err(e) => return self.fail(event_loop, e),
            }
            event_loop.exit();
        }
    }

    /// Sprays rays in a cone through the cursor and adds their points.
    fn spray(&mut self, event_loop: &ActiveEventLoop) {
        let Some(a) = &mut self.active else { return };
        if self.tracer.is_none() {
            match Tracer::new(&self.scene) {
                Ok(t) => self.tracer = Some(t),
                Err(e) => return self.fail(event_loop, e),
            }
        }
        let tracer = self.tracer.as_ref().expect("built above");
        let (w, h) = (a.config.width as f32, a.config.height as f32);
        let x = (2.0 * self.cursor.0 as f32 / w - 1.0).clamp(-1.0, 1.0);
        let y = (1.0 - 2.0 * self.cursor.1 as f32 / h).clamp(-1.0, 1.0);
        let camera = self.orbit.camera();
        self.sprays += 1;
        let o = SprayOptions { rays: self.opts.spray_rays, seed: self.sprays, ..SprayOptions::default() };
        let new = tracer.spray_cone(camera.eye, camera.ray(w / h, x, y), self.opts.spray_degrees.to_radians(), &o);
        if let Err(e) = a.renderer.add_points(&mut a.uploaded, &new) {
            return self.fail(event_loop, e);
        }
        self.points.extend_from_slice(&new);
    }

    fn key(&mut self, code: KeyCode, event_loop: &ActiveEventLoop) {
        let (fwd, right) = self.orbit.axes();
        let step = self.orbit.distance * 0.05;
        let mut up = Vec3::ZERO;
        up[self.orbit.up] = 1.0;
        match code {
            KeyCode::Escape => event_loop.exit(),
            KeyCode::KeyC => {
                let at = Culling::ALL.iter().position(|&c| c == self.culling).unwrap_or(0);
                self.culling = Culling::ALL[(at + 1) % Culling::ALL.len()];
            }
            KeyCode::KeyZ => self.prepass = !self.prepass,
            KeyCode::KeyG => self.gamma = !self.gamma,
            KeyCode::KeyL => self.light_grid = !self.light_grid,
            KeyCode::KeyM => self.mesh = !self.mesh,
            KeyCode::KeyB => self.boxes = !self.boxes,
            KeyCode::KeyT => self.text = !self.text,
            KeyCode::KeyP => self.spray(event_loop),
            KeyCode::KeyX => {
                self.points.clear();
                if let Some(a) = &mut self.active {
                    a.renderer.clear_points(&mut a.uploaded);
                }
            }
            KeyCode::KeyR => self.orbit = Orbit::from_camera(&self.home, self.orbit.up),
            KeyCode::KeyW => self.orbit.target += fwd * step,
            KeyCode::KeyS => self.orbit.target -= fwd * step,
            KeyCode::KeyD => self.orbit.target += right * step,
            KeyCode::KeyA => self.orbit.target -= right * step,
            KeyCode::KeyE => self.orbit.target += up * step,
            KeyCode::KeyQ => self.orbit.target -= up * step,
            _ => {}
        }
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.active.is_some() {
            return;
        }
        match self.open(event_loop) {
            Ok(a) => {
                a.window.request_redraw();
                self.active = Some(a);
            }
            Err(e) => self.fail(event_loop, e),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                if let Some(a) = &mut self.active {
                    a.config.width = size.width.clamp(1, a.renderer.max_side());
                    a.config.height = size.height.clamp(1, a.renderer.max_side());
                    a.surface.configure(&a.renderer.dev.device, &a.config);
                }
            }
            WindowEvent::RedrawRequested => self.draw(event_loop),
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                if let PhysicalKey::Code(code) = event.physical_key {
                    self.key(code, event_loop);
                }
            }
            WindowEvent::MouseInput { state: ElementState::Pressed, button: MouseButton::Middle, .. } => self.spray(event_loop),
            WindowEvent::MouseInput { state, button, .. } => {
                self.drag = (state == ElementState::Pressed).then_some((button, self.cursor));
            }
            WindowEvent::CursorMoved { position, .. } => {
                let (x, y) = (position.x, position.y);
                if let Some((button, (px, py))) = self.drag {
                    let (dx, dy) = ((x - px) as f32, (y - py) as f32);
                    match button {
                        MouseButton::Left => {
                            self.orbit.yaw += dx * 0.01;
                            self.orbit.pitch = (self.orbit.pitch + dy * 0.01).clamp(-1.55, 1.55);
                        }
                        _ => {
                            let (fwd, right) = self.orbit.axes();
                            let up = right.cross(fwd);
                            let k = self.orbit.distance * 0.002;
                            self.orbit.target += (-right * dx + up * dy) * k;
                        }
                    }
                    self.drag = Some((button, (x, y)));
                }
                self.cursor = (x, y);
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.orbit.distance = (self.orbit.distance * 0.9f32.powf(lines)).max(1e-6);
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(a) = &self.active {
            a.window.request_redraw();
        }
    }
}
