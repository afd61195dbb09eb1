//! The 3D view on the GPU: the stage's lit triangles (`scene::solid`) drawn with wgpu
//! into an offscreen target of the viewport's size — 4× multisampled, with a depth buffer
//! — then copied into egui's frame where the viewport is, through an egui paint callback.
//! Opaque solids first; then the translucent ones (shadows, ghost poses) blended over them
//! without writing depth. The marks the user works with (trajectories, handles, pins,
//! force arrows, labels) are painted by egui on top. Used when the editor runs on wgpu
//! (eframe's default renderer, and the kittest harness with `.wgpu()`); otherwise the
//! viewport paints its 2D marks.

use crate::scene::solid::{Mesh, Vertex};
use eframe::egui_wgpu::{self, CallbackResources, CallbackTrait, ScreenDescriptor};
use eframe::{egui, wgpu};
use glam::{Mat4, Vec3};

/// Samples per pixel of the offscreen target.
const SAMPLES: u32 = 4;
const COLOUR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// The shader of the solids: the key light from above the player's right shoulder, a sky
/// and ground fill, a little specular and rim light; colours linear in, gamma 2.2 out.
const SOLID_SHADER: &str = r#"
struct Globals { view_proj: mat4x4<f32>, eye: vec4<f32>, light: vec4<f32> };
@group(0) @binding(0) var<uniform> g: Globals;
struct VIn {
  @location(0) position: vec3<f32>, @location(1) normal: vec3<f32>,
  @location(2) colour: vec4<f32>, @location(3) shading: f32,
};
struct VOut {
  @builtin(position) clip: vec4<f32>, @location(0) world: vec3<f32>,
  @location(1) normal: vec3<f32>, @location(2) colour: vec4<f32>, @location(3) shading: f32,
};
@vertex fn vs(v: VIn) -> VOut {
  var o: VOut;
  o.clip = g.view_proj * vec4<f32>(v.position, 1.0);
  o.world = v.position; o.normal = v.normal; o.colour = v.colour; o.shading = v.shading;
  return o;
}
@fragment fn fs(f: VOut) -> @location(0) vec4<f32> {
  if (f.shading > 0.5 && f.shading < 1.5) {
    return vec4<f32>(pow(f.colour.rgb, vec3<f32>(1.0 / 2.2)), f.colour.a);
  }
  var base = f.colour.rgb;
  if (f.shading > 1.5) {
    let cells = f.world.xy / 0.25;
    let d = abs(fract(cells - 0.5) - 0.5) / max(fwidth(cells), vec2<f32>(1e-4));
    let line = 1.0 - min(min(d.x, d.y), 1.0);
    base = mix(base, vec3<f32>(0.11, 0.115, 0.13), 0.7 * line);
  }
  let n = normalize(f.normal);
  let l = normalize(g.light.xyz);
  let v = normalize(g.eye.xyz - f.world);
  let diffuse = max(dot(n, l), 0.0);
  let sky = 0.5 + 0.5 * n.z;
  let ambient = mix(vec3<f32>(0.10, 0.09, 0.08), vec3<f32>(0.30, 0.33, 0.40), sky);
  let h = normalize(l + v);
  let spec = 0.25 * pow(max(dot(n, h), 0.0), 48.0) * step(0.0, dot(n, l));
  let rim = 0.12 * pow(1.0 - max(dot(n, v), 0.0), 3.0);
  let lit = base * (ambient + 0.9 * diffuse) + vec3<f32>(spec + rim);
  return vec4<f32>(pow(lit, vec3<f32>(1.0 / 2.2)), f.colour.a);
}
"#;

/// The shader that copies the offscreen image into egui's frame (a full-viewport triangle).
const BLIT_SHADER: &str = r#"
@group(0) @binding(0) var image: texture_2d<f32>;
@group(0) @binding(1) var image_sampler: sampler;
struct VOut { @builtin(position) clip: vec4<f32>, @location(0) uv: vec2<f32> };
@vertex fn vs(@builtin(vertex_index) i: u32) -> VOut {
  let xy = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
  var o: VOut;
  o.clip = vec4<f32>(xy * 2.0 - 1.0, 0.0, 1.0);
  o.uv = vec2<f32>(xy.x, 1.0 - xy.y);
  return o;
}
@fragment fn fs(f: VOut) -> @location(0) vec4<f32> {
  return textureSample(image, image_sampler, f.uv);
}
"#;

/// Uniforms of the solid shader.
#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct Globals {
    view_proj: [[f32; 4]; 4],
    eye: [f32; 4],
    light: [f32; 4],
}

/// One frame of the 3D view: what to draw and with which camera.
pub struct Frame {
    pub opaque: Mesh,
    /// Shadows and ghosts, blended over the opaque solids.
    pub translucent: Mesh,
    pub view_proj: Mat4,
    pub eye: Vec3,
    /// Background, linear RGB.
    pub background: [f64; 3],
    /// egui's target format (for the copy into its frame).
    pub target_format: wgpu::TextureFormat,
}

/// The paint callback of one frame, and the viewport's size in points.
pub struct Callback(std::sync::Arc<Frame>, [f32; 2]);

/// The viewport-sized targets.
struct Targets {
    size: [u32; 2],
    msaa: wgpu::TextureView,
    resolved: wgpu::TextureView,
    depth: wgpu::TextureView,
    blit_group: wgpu::BindGroup,
}

/// Pipelines and buffers, made once (kept in egui's callback resources).
struct Resources {
    opaque: wgpu::RenderPipeline,
    translucent: wgpu::RenderPipeline,
    blit: wgpu::RenderPipeline,
    blit_layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    globals: wgpu::Buffer,
    globals_group: wgpu::BindGroup,
    vertices: Option<wgpu::Buffer>,
    indices: Option<wgpu::Buffer>,
    targets: Option<Targets>,
    /// Index ranges drawn last frame: (opaque count, translucent count).
    counts: (u32, u32),
}

impl Resources {
    fn new(device: &wgpu::Device, target_format: wgpu::TextureFormat) -> Resources {
        let globals = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("stage globals"),
            size: std::mem::size_of::<Globals>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let globals_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("stage globals"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            }],
        });
        let globals_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("stage globals"),
            layout: &globals_layout,
            entries: &[wgpu::BindGroupEntry {
                binding: 0,
                resource: globals.as_entire_binding(),
            }],
        });
        let solid = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("stage solids"),
            source: wgpu::ShaderSource::Wgsl(SOLID_SHADER.into()),
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("stage solids"),
            bind_group_layouts: &[Some(&globals_layout)],
            immediate_size: 0,
        });
        let attributes = wgpu::vertex_attr_array![
            0 => Float32x3, 1 => Float32x3, 2 => Float32x4, 3 => Float32
        ];
        let solid_pipeline = |blend: Option<wgpu::BlendState>, write_depth: bool, cull: bool| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some("stage solids"),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &solid,
                    entry_point: Some("vs"),
                    compilation_options: Default::default(),
                    buffers: &[Some(wgpu::VertexBufferLayout {
                        array_stride: std::mem::size_of::<Vertex>() as u64,
                        step_mode: wgpu::VertexStepMode::Vertex,
                        attributes: &attributes,
                    })],
                },
                primitive: wgpu::PrimitiveState {
                    cull_mode: cull.then_some(wgpu::Face::Back),
                    ..Default::default()
                },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: DEPTH_FORMAT,
                    depth_write_enabled: Some(write_depth),
                    depth_compare: Some(wgpu::CompareFunction::LessEqual),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: wgpu::MultisampleState {
                    count: SAMPLES,
                    ..Default::default()
                },
                fragment: Some(wgpu::FragmentState {
                    module: &solid,
                    entry_point: Some("fs"),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: COLOUR_FORMAT,
                        blend,
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        // Heads and the floor are seen from above only, but a head's underside shows from
        // a low camera: no culling for the opaque pass.
        let opaque = solid_pipeline(None, true, false);
        let translucent = solid_pipeline(Some(wgpu::BlendState::ALPHA_BLENDING), false, true);
        let blit_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("stage image"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        multisampled: false,
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let blit_module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("stage image"),
            source: wgpu::ShaderSource::Wgsl(BLIT_SHADER.into()),
        });
        let blit_pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("stage image"),
            bind_group_layouts: &[Some(&blit_layout)],
            immediate_size: 0,
        });
        let blit = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("stage image"),
            layout: Some(&blit_pipeline_layout),
            vertex: wgpu::VertexState {
                module: &blit_module,
                entry_point: Some("vs"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: Default::default(),
            depth_stencil: None,
            multisample: Default::default(),
            fragment: Some(wgpu::FragmentState {
                module: &blit_module,
                entry_point: Some("fs"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: target_format,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("stage image"),
            mag_filter: wgpu::FilterMode::Linear,
            min_filter: wgpu::FilterMode::Linear,
            ..Default::default()
        });
        Resources {
            opaque,
            translucent,
            blit,
            blit_layout,
            sampler,
            globals,
            globals_group,
            vertices: None,
            indices: None,
            targets: None,
            counts: (0, 0),
        }
    }

    /// Make the targets `size` px (again when the size changes).
    fn fit_targets(&mut self, device: &wgpu::Device, size: [u32; 2]) {
        if self.targets.as_ref().is_none_or(|t| t.size != size) {
            let texture = |label, format, samples, usage| {
                device
                    .create_texture(&wgpu::TextureDescriptor {
                        label: Some(label),
                        size: wgpu::Extent3d {
                            width: size[0],
                            height: size[1],
                            depth_or_array_layers: 1,
                        },
                        mip_level_count: 1,
                        sample_count: samples,
                        dimension: wgpu::TextureDimension::D2,
                        format,
                        usage,
                        view_formats: &[],
                    })
                    .create_view(&Default::default())
            };
            let attach = wgpu::TextureUsages::RENDER_ATTACHMENT;
            let resolved = texture(
                "stage image",
                COLOUR_FORMAT,
                1,
                attach | wgpu::TextureUsages::TEXTURE_BINDING,
            );
            let blit_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("stage image"),
                layout: &self.blit_layout,
                entries: &[
                    wgpu::BindGroupEntry {
                        binding: 0,
                        resource: wgpu::BindingResource::TextureView(&resolved),
                    },
                    wgpu::BindGroupEntry {
                        binding: 1,
                        resource: wgpu::BindingResource::Sampler(&self.sampler),
                    },
                ],
            });
            self.targets = Some(Targets {
                size,
                msaa: texture("stage samples", COLOUR_FORMAT, SAMPLES, attach),
                resolved,
                depth: texture("stage depth", DEPTH_FORMAT, SAMPLES, attach),
                blit_group,
            });
        }
    }
}

/// A buffer holding `bytes`, grown (by powers of two) when they do not fit.
fn upload(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    slot: &mut Option<wgpu::Buffer>,
    bytes: &[u8],
    usage: wgpu::BufferUsages,
) {
    let need = (bytes.len() as u64).max(4).next_power_of_two();
    if slot.as_ref().is_none_or(|b| b.size() < need) {
        *slot = Some(device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("stage mesh"),
            size: need,
            usage: usage | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        }));
    }
    if !bytes.is_empty() {
        queue.write_buffer(slot.as_ref().expect("made above"), 0, bytes);
    }
}

impl CallbackTrait for Callback {
    fn prepare(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        screen: &ScreenDescriptor,
        encoder: &mut wgpu::CommandEncoder,
        resources: &mut CallbackResources,
    ) -> Vec<wgpu::CommandBuffer> {
        let frame = &self.0;
        if resources.get::<Resources>().is_none() {
            resources.insert(Resources::new(device, frame.target_format));
        }
        let res = resources.get_mut::<Resources>().expect("inserted above");
        // One mesh: the opaque vertices, then the translucent ones (their indices moved).
        let base = frame.opaque.vertices.len() as u32;
        let vertices: Vec<Vertex> = (frame.opaque.vertices.iter())
            .chain(&frame.translucent.vertices)
            .copied()
            .collect();
        let indices: Vec<u32> = (frame.opaque.indices.iter().copied())
            .chain(frame.translucent.indices.iter().map(|i| i + base))
            .collect();
        upload(
            device,
            queue,
            &mut res.vertices,
            bytemuck::cast_slice(&vertices),
            wgpu::BufferUsages::VERTEX,
        );
        upload(
            device,
            queue,
            &mut res.indices,
            bytemuck::cast_slice(&indices),
            wgpu::BufferUsages::INDEX,
        );
        res.counts = (
            frame.opaque.indices.len() as u32,
            frame.translucent.indices.len() as u32,
        );
        let globals = Globals {
            view_proj: frame.view_proj.to_cols_array_2d(),
            eye: frame.eye.extend(1.0).to_array(),
            light: Vec3::new(0.45, -0.55, 0.8)
                .normalize()
                .extend(0.0)
                .to_array(),
        };
        queue.write_buffer(&res.globals, 0, bytemuck::bytes_of(&globals));
        res.fit_targets(device, self.size_px(screen.pixels_per_point));
        let res = &*res;
        let (Some(vb), Some(ib), Some(targets)) = (&res.vertices, &res.indices, &res.targets)
        else {
            return Vec::new();
        };
        let [r, g, b] = frame.background.map(|c| c.powf(1.0 / 2.2));
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("stage"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &targets.msaa,
                depth_slice: None,
                resolve_target: Some(&targets.resolved),
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color { r, g, b, a: 1.0 }),
                    store: wgpu::StoreOp::Discard,
                },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &targets.depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(1.0),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            ..Default::default()
        });
        let counts = res.counts;
        pass.set_bind_group(0, &res.globals_group, &[]);
        pass.set_vertex_buffer(0, vb.slice(..));
        pass.set_index_buffer(ib.slice(..), wgpu::IndexFormat::Uint32);
        pass.set_pipeline(&res.opaque);
        pass.draw_indexed(0..counts.0, 0, 0..1);
        pass.set_pipeline(&res.translucent);
        pass.draw_indexed(counts.0..counts.0 + counts.1, 0, 0..1);
        drop(pass);
        Vec::new()
    }

    fn paint(
        &self,
        _info: egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        resources: &CallbackResources,
    ) {
        let Some(res) = resources.get::<Resources>() else {
            return;
        };
        let Some(targets) = &res.targets else {
            return;
        };
        pass.set_pipeline(&res.blit);
        pass.set_bind_group(0, &targets.blit_group, &[]);
        pass.draw(0..3, 0..1);
    }
}

impl Callback {
    /// The offscreen image's size for `pixels_per_point`, px (at least 1 × 1).
    fn size_px(&self, pixels_per_point: f32) -> [u32; 2] {
        let [w, h] = self.1;
        [
            ((w * pixels_per_point).round() as u32).max(1),
            ((h * pixels_per_point).round() as u32).max(1),
        ]
    }
}

/// Add the 3D view of `frame` to `painter` over `rect` (points).
pub fn paint(painter: &egui::Painter, rect: egui::Rect, frame: Frame) {
    painter.add(egui_wgpu::Callback::new_paint_callback(
        rect,
        Callback(std::sync::Arc::new(frame), [rect.width(), rect.height()]),
    ));
}
