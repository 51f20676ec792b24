//! glTF 2.0 scenes (`.glb`, or `.gltf` with its files beside it) through the `gltf` crate, turned
//! into what the OBJ reader hands on (faces indexing positions, materials), so that both go
//! through the same building, merging and checks (`load::build_scene`).
//!
//! - **Geometry**: the triangles of every mesh a node of the scene instances, in world space (the
//!   node's transform times its parents'); a node whose transform mirrors has its triangles'
//!   winding reversed, so that their front stays the front (glTF's rule). Points and lines are
//!   skipped and counted.
//! - **Materials**: `baseColorFactor` (times the mean of `baseColorTexture`, sRGB-decoded) is the
//!   reflectance `Kd`; `emissiveFactor` (times `KHR_materials_emissive_strength` and the mean of
//!   `emissiveTexture`) the emitted radiance `Ke`. A primitive without a material gets the OBJ
//!   reader's grey default, not glTF's white: a white world reflects all light and never converges.
//! - **Camera**: the first perspective camera met walking the scene's nodes.
//! - **Hostile files** (`gltf_data.rs`): buffers and images only from the GLB chunk, `data:` URIs
//!   or the scene's folder; every byte range and index checked; NaN/inf refused; at most
//!   [`MAX_TRIANGLES`] triangles after instancing. Each error names the file and the node or mesh.

use super::emission::LoadOptions;
use super::error::{SceneError, MAX_KE};
use super::files::{shown, shown_path};
use super::gltf_data::Buffers;
use super::libraries::Materials;
use super::load::{build_scene, read_scene_file, Parsed};
use super::obj::{Face, ObjFile};
use super::{Camera, Material, DEFAULT_GREY, DEFAULT_MATERIAL};
use glam::{Mat4, Vec3};
use gltf::mesh::Mode;
use std::collections::HashMap;
use std::path::Path;

/// Most triangles a glTF scene may have after its meshes are instanced (a small file can
/// instance one mesh many times over): far beyond what the solver handles.
pub const MAX_TRIANGLES: usize = 1 << 25;

/// Is `path` a glTF file, by its extension (`.glb`, `.gltf`, any case)?
pub fn is_gltf(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("glb") || e.eq_ignore_ascii_case("gltf"))
}

/// The scene in the glTF file `path`.
pub fn load_gltf(path: &Path) -> Result<super::Scene, SceneError> {
    load_gltf_with(path, &LoadOptions::default())
}

/// [`load_gltf`] with `options` applied (emission overrides by material name, `--keep-faces`).
pub fn load_gltf_with(path: &Path, options: &LoadOptions) -> Result<super::Scene, SceneError> {
    let (bytes, dir) = read_scene_file(path)?;
    let bad = |what: String| SceneError::Parse {
        path: shown_path(path),
        line: String::new(),
        what,
    };
    let file = gltf::Gltf::from_slice(&bytes).map_err(|e| {
        bad(format!(
            "not a valid glTF 2.0 file: {}",
            shown(&e.to_string())
        ))
    })?;
    drop(bytes);
    let doc = &file.document;
    let buffers = Buffers::read(doc, file.blob.clone(), dir).map_err(&bad)?;
    let mut messages = Vec::new();
    let materials = read_materials(path, doc, &buffers, dir, &mut messages).map_err(&bad)?;
    let mut walk = Walk {
        buffers: &buffers,
        obj: ObjFile {
            material_names: materials.list[..materials.list.len() - 1]
                .iter()
                .map(|m| m.name.clone())
                .collect(),
            ..Default::default()
        },
        meshes: HashMap::new(),
        reached: vec![false; doc.nodes().len()],
        camera: None,
        skipped: 0,
    };
    let scene = doc
        .default_scene()
        .or_else(|| doc.scenes().next())
        .ok_or_else(|| bad("the file has no scene".into()))?;
    for node in scene.nodes() {
        walk.node(&node, Mat4::IDENTITY).map_err(&bad)?;
    }
    if walk.skipped > 0 {
        messages.push(format!(
            "note: {}: skipped {} primitive(s) of points or lines",
            shown_path(path),
            walk.skipped
        ));
    }
    let parsed = Parsed {
        obj: walk.obj,
        materials,
        camera: walk.camera,
        patch_size: None,
        keep_faces: false,
        messages,
    };
    build_scene(path, parsed, false, options)
}

/// A node's or mesh's name for messages: `'name' (node 3)`, or `node 3`.
fn label(kind: &str, name: Option<&str>, index: usize) -> String {
    match name {
        Some(n) => format!("{kind} '{}' ({index})", shown(n)),
        None => format!("{kind} {index}"),
    }
}

/// One primitive of a mesh, in the mesh's space.
struct Primitive {
    positions: Vec<Vec3>,
    triangles: Vec<[u32; 3]>,
    material: Option<u32>,
}

/// The walk over the scene's node trees, collecting the faces of every mesh instance.
struct Walk<'a> {
    buffers: &'a Buffers,
    obj: ObjFile,
    /// Each mesh's primitives, read once however often it is instanced.
    meshes: HashMap<usize, std::rc::Rc<Vec<Primitive>>>,
    /// Nodes already reached: a node reached twice (two parents, a cycle) is refused.
    reached: Vec<bool>,
    camera: Option<Camera>,
    /// Primitives of points or lines.
    skipped: usize,
}

impl Walk<'_> {
    fn node(&mut self, node: &gltf::Node, parent: Mat4) -> Result<(), String> {
        // Depth first with an explicit stack: a hierarchy thousands deep must not overflow ours.
        let mut stack = vec![(node.clone(), parent)];
        while let Some((node, parent)) = stack.pop() {
            let name = label("node", node.name(), node.index());
            if std::mem::replace(&mut self.reached[node.index()], true) {
                return Err(format!(
                    "{name} is reached twice in the scene's hierarchy (a node with two parents, \
                     or a cycle)"
                ));
            }
            let local = Mat4::from_cols_array_2d(&node.transform().matrix());
            let world = parent * local;
            if !world.is_finite() {
                return Err(format!("{name}: its transform is not finite"));
            }
            if let Some(mesh) = node.mesh() {
                self.instance(&mesh, world, &node)?;
            }
            if let (None, Some(camera)) = (self.camera, node.camera()) {
                self.camera = camera_of(&camera, world).map_err(|e| format!("{name}: {e}"))?;
            }
            // Reversed, so that children are visited in their order.
            let children: Vec<_> = node.children().collect();
            stack.extend(children.into_iter().rev().map(|c| (c, world)));
        }
        Ok(())
    }

    /// Add the faces of `mesh` placed by `world`.
    fn instance(
        &mut self,
        mesh: &gltf::Mesh,
        world: Mat4,
        node: &gltf::Node,
    ) -> Result<(), String> {
        let at = |e: String| {
            format!(
                "{}, {}: {e}",
                label("node", node.name(), node.index()),
                label("mesh", mesh.name(), mesh.index())
            )
        };
        let primitives = match self.meshes.get(&mesh.index()) {
            Some(p) => p.clone(),
            None => {
                let p = std::rc::Rc::new(self.read_mesh(mesh).map_err(at)?);
                self.meshes.insert(mesh.index(), p.clone());
                p
            }
        };
        let mirrored = world.determinant() < 0.0;
        // Plain names for the messages that quote objects: `room/wall`, `node 3/mesh 0`.
        let plain = |kind: &str, name: Option<&str>, i: usize| {
            name.map_or_else(|| format!("{kind} {i}"), shown)
        };
        self.obj.object_names.push(format!(
            "{}/{}",
            plain("node", node.name(), node.index()),
            plain("mesh", mesh.name(), mesh.index())
        ));
        let object = self.obj.object_names.len() as u32 - 1;
        for p in primitives.iter() {
            if self.obj.faces.len() + p.triangles.len() > MAX_TRIANGLES {
                return Err(at(format!(
                    "the scene has more than {MAX_TRIANGLES} triangles once its meshes are \
                     placed by their nodes"
                )));
            }
            let base = self.obj.positions.len() as u32;
            for (k, &v) in p.positions.iter().enumerate() {
                let w = world.transform_point3(v);
                if !w.is_finite() {
                    return Err(at(format!("vertex {k} is not finite once transformed")));
                }
                self.obj.positions.push(w);
            }
            for t in &p.triangles {
                let start = self.obj.corners.len() as u32;
                let t = if mirrored { [t[0], t[2], t[1]] } else { *t };
                self.obj.corners.extend(t.iter().map(|&i| base + i));
                self.obj.faces.push(Face {
                    start,
                    len: 3,
                    material: p.material,
                    object,
                });
            }
        }
        Ok(())
    }

    fn read_mesh(&mut self, mesh: &gltf::Mesh) -> Result<Vec<Primitive>, String> {
        let mut out = Vec::new();
        for (k, p) in mesh.primitives().enumerate() {
            let at = |e: String| format!("primitive {k}: {e}");
            if !matches!(
                p.mode(),
                Mode::Triangles | Mode::TriangleStrip | Mode::TriangleFan
            ) {
                self.skipped += 1;
                continue;
            }
            let accessor = p
                .get(&gltf::Semantic::Positions)
                .ok_or_else(|| at("it has no POSITION attribute".into()))?;
            let positions = self.buffers.positions(&accessor).map_err(at)?;
            if let Some(i) = positions
                .iter()
                .position(|v| !v.iter().all(|c| c.is_finite()))
            {
                return Err(at(format!(
                    "vertex {i} of accessor {} is not three finite numbers",
                    accessor.index()
                )));
            }
            let n = positions.len();
            let indices = match p.indices() {
                Some(a) => {
                    let indices = self.buffers.indices(&a).map_err(at)?;
                    if let Some(&i) = indices.iter().find(|&&i| i as usize >= n) {
                        return Err(at(format!(
                            "index {i} of accessor {} is out of range: there are {n} vertices",
                            a.index()
                        )));
                    }
                    indices
                }
                None => (0..n as u32).collect(),
            };
            out.push(Primitive {
                positions: positions.into_iter().map(Vec3::from).collect(),
                triangles: triangles(p.mode(), &indices).map_err(at)?,
                material: p.material().index().map(|m| m as u32),
            });
        }
        Ok(out)
    }
}

/// The triangles of a primitive's index list, each counter-clockwise when the file's are.
fn triangles(mode: Mode, indices: &[u32]) -> Result<Vec<[u32; 3]>, String> {
    Ok(match mode {
        Mode::Triangles => {
            if !indices.len().is_multiple_of(3) {
                return Err(format!(
                    "{} indices do not make whole triangles",
                    indices.len()
                ));
            }
            indices
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect()
        }
        // Every other triangle of a strip runs the other way round; swapping two corners turns
        // it back (the spec's order: i, i+1, i+2 for even i, i+1, i, i+2 for odd).
        Mode::TriangleStrip => (2..indices.len())
            .map(|i| {
                let (a, b, c) = (indices[i - 2], indices[i - 1], indices[i]);
                if i % 2 == 0 {
                    [a, b, c]
                } else {
                    [b, a, c]
                }
            })
            .collect(),
        Mode::TriangleFan => (2..indices.len())
            .map(|i| [indices[0], indices[i - 1], indices[i]])
            .collect(),
        _ => Vec::new(),
    })
}

/// The camera a perspective glTF camera placed by `world` is: it looks down its −Z with +Y up.
fn camera_of(camera: &gltf::Camera, world: Mat4) -> Result<Option<Camera>, String> {
    let gltf::camera::Projection::Perspective(p) = camera.projection() else {
        return Ok(None);
    };
    let eye = world.w_axis.truncate();
    let forward = -world.z_axis.truncate();
    let reach = eye.length().max(1.0);
    let c = Camera {
        eye,
        target: eye + forward.normalize_or_zero() * reach,
        up: world.y_axis.truncate(),
        fov_y: p.yfov().to_degrees(),
    };
    c.validate()
        .map_err(|e| format!("{}: {e}", label("camera", camera.name(), camera.index())))?;
    Ok(Some(c))
}

/// The file's materials (the grey default last), each index its own `usemtl` name.
fn read_materials(
    path: &Path,
    doc: &gltf::Document,
    buffers: &Buffers,
    dir: &Path,
    messages: &mut Vec<String>,
) -> Result<Materials, String> {
    let mut means: HashMap<usize, [f32; 3]> = HashMap::new();
    let mut mean = |info: Option<gltf::texture::Info>| -> Result<Vec3, String> {
        let Some(info) = info else {
            return Ok(Vec3::ONE);
        };
        let image = info.texture().source();
        if let Some(m) = means.get(&image.index()) {
            return Ok(Vec3::from(*m));
        }
        let m = buffers.image_mean(&image, dir)?;
        means.insert(image.index(), m);
        Ok(Vec3::from(m))
    };
    let mut list = Vec::new();
    for m in doc.materials() {
        let i = m.index().unwrap_or(0);
        let name = match m.name() {
            Some(n) => shown(n),
            None => format!("material_{i}"),
        };
        let at = |e: String| format!("{}: {e}", label("material", m.name(), i));
        let pbr = m.pbr_metallic_roughness();
        let f = pbr.base_color_factor();
        let kd = Vec3::new(f[0], f[1], f[2]) * mean(pbr.base_color_texture()).map_err(at)?;
        if !(kd.is_finite() && kd.min_element() >= 0.0) {
            return Err(at(format!(
                "baseColorFactor {:?} is not three numbers from 0 to 1",
                kd.to_array()
            )));
        }
        if kd.max_element() > 1.0 {
            messages.push(format!(
                "warning: {}: material '{name}' has a base colour {kd}, above 1: clamped to 1",
                shown_path(path)
            ));
        }
        let strength = m.emissive_strength().unwrap_or(1.0);
        let ke =
            Vec3::from(m.emissive_factor()) * strength * mean(m.emissive_texture()).map_err(at)?;
        if !(ke.is_finite() && ke.min_element() >= 0.0 && ke.max_element() <= MAX_KE) {
            return Err(at(format!(
                "the emitted radiance (emissiveFactor × emissive strength) {:?} is not three \
                 numbers from 0 to {MAX_KE:e}",
                ke.to_array()
            )));
        }
        list.push(Material {
            name,
            kd: kd.min(Vec3::ONE),
            ke,
        });
    }
    let of_name = (0..list.len()).collect();
    list.push(Material {
        name: DEFAULT_MATERIAL.into(),
        kd: Vec3::splat(DEFAULT_GREY),
        ke: Vec3::ZERO,
    });
    Ok(Materials { list, of_name })
}
