//! Shader programs, built in the order of the paper's section 2.2: create shader objects, give
//! them source, compile, create the program, attach, bind attribute locations (step 9, before
//! linking), link, use, and look up uniforms after linking (step 8).

use super::check::GlError;
use super::Gl;
use glow::HasContext;
use std::cell::RefCell;
use std::collections::HashMap;

/// A shader stage's source and the file it came from (for error messages).
pub struct Source {
    /// The file under glsl/ that messages name.
    pub file: &'static str,
    /// The GLSL source, with any `#define`s put in after `#version`.
    pub text: std::borrow::Cow<'static, str>,
}

impl Source {
    /// The same source with `text` inserted after its `#version` line: GLSL 1.30 has no
    /// `#include`, so functions several files share live in one file inserted into each.
    /// `#line` keeps the compiler's line numbers those of the file.
    pub fn insert(self, text: &str) -> Source {
        let (version, rest) = self.text.split_once('\n').unwrap_or((&self.text, ""));
        let text = format!("{version}\n{text}\n#line 2\n{rest}");
        Source {
            file: self.file,
            text: text.into(),
        }
    }

    /// The same source with `text` appended: the host's definitions of functions the file
    /// declares and calls (GLSL lets a declared function be defined after its callers).
    pub fn append(self, text: &str) -> Source {
        Source {
            file: self.file,
            text: format!("{}\n{text}", self.text).into(),
        }
    }

    /// The same source with `#define name value` (a compile-time variant: llvmpipe runs both
    /// sides of a branch, even on a uniform).
    pub fn define(self, name: &str, value: i32) -> Source {
        self.insert(&format!("#define {name} {value}"))
    }
}

/// Embed a file of `glsl/` at build time.
#[macro_export]
macro_rules! glsl {
    ($name:literal) => {
        $crate::gl::program::Source {
            file: concat!("glsl/", $name),
            text: std::borrow::Cow::Borrowed(include_str!(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/glsl/",
                $name
            ))),
        }
    };
}

/// A linked shader program whose uniform locations are looked up once, by name.
pub struct Program {
    gl: Gl,
    raw: glow::Program,
    uniforms: RefCell<HashMap<&'static str, Option<glow::UniformLocation>>>,
}

impl Program {
    /// Compile and link `vertex` and `fragment`; a failure names the files and gives the log.
    pub fn new(
        gl: &Gl,
        vertex: Source,
        fragment: Source,
        attributes: &[(u32, &str)],
        outputs: &[(u32, &str)],
    ) -> Result<Program, GlError> {
        unsafe {
            let program = gl.create_program().map_err(GlError::Limit)?;
            let mut shaders = Vec::new();
            for (stage, src) in [
                (glow::VERTEX_SHADER, &vertex),
                (glow::FRAGMENT_SHADER, &fragment),
            ] {
                let shader = gl.create_shader(stage).map_err(GlError::Limit)?;
                gl.shader_source(shader, &src.text);
                gl.compile_shader(shader);
                if !gl.get_shader_compile_status(shader) {
                    let log = gl.get_shader_info_log(shader);
                    gl.delete_shader(shader);
                    gl.delete_program(program);
                    return Err(GlError::Compile {
                        file: src.file.into(),
                        log,
                    });
                }
                gl.attach_shader(program, shader);
                shaders.push(shader);
            }
            for &(location, name) in attributes {
                gl.bind_attrib_location(program, location, name);
            }
            // GLSL 1.30 has no layout qualifiers: colour outputs are bound by name too.
            for &(index, name) in outputs {
                gl.bind_frag_data_location(program, index, name);
            }
            gl.link_program(program);
            for s in shaders {
                gl.detach_shader(program, s);
                gl.delete_shader(s);
            }
            if !gl.get_program_link_status(program) {
                let log = gl.get_program_info_log(program);
                gl.delete_program(program);
                return Err(GlError::Link {
                    files: format!("{}, {}", vertex.file, fragment.file),
                    log,
                });
            }
            Ok(Program {
                gl: gl.clone(),
                raw: program,
                uniforms: RefCell::new(HashMap::new()),
            })
        }
    }

    /// Make this the current program (the setters below need it bound).
    pub fn use_program(&self) {
        unsafe { self.gl.use_program(Some(self.raw)) }
    }

    fn location(&self, name: &'static str) -> Option<glow::UniformLocation> {
        *self
            .uniforms
            .borrow_mut()
            .entry(name)
            .or_insert_with(|| unsafe { self.gl.get_uniform_location(self.raw, name) })
    }

    // Setters for the bound program; a uniform the compiler removed is silently skipped.
    /// Set the uniform `name`, an `int` (or a sampler's unit).
    pub fn set_i32(&self, name: &'static str, v: i32) {
        unsafe { self.gl.uniform_1_i32(self.location(name).as_ref(), v) }
    }
    /// Set the uniform `name`, a `float`.
    pub fn set_f32(&self, name: &'static str, v: f32) {
        unsafe { self.gl.uniform_1_f32(self.location(name).as_ref(), v) }
    }
    /// Set the uniform `name`, a `vec2`.
    pub fn set_vec2(&self, name: &'static str, v: [f32; 2]) {
        unsafe {
            self.gl
                .uniform_2_f32(self.location(name).as_ref(), v[0], v[1])
        }
    }
    /// Set the uniform `name`, a `vec3`.
    pub fn set_vec3(&self, name: &'static str, v: [f32; 3]) {
        unsafe {
            self.gl
                .uniform_3_f32(self.location(name).as_ref(), v[0], v[1], v[2])
        }
    }
    /// Set the uniform `name`, a `vec4`.
    pub fn set_vec4(&self, name: &'static str, v: [f32; 4]) {
        unsafe {
            self.gl
                .uniform_4_f32(self.location(name).as_ref(), v[0], v[1], v[2], v[3])
        }
    }
    /// Set the uniform `name`, an `ivec4`.
    pub fn set_ivec4(&self, name: &'static str, v: [i32; 4]) {
        unsafe {
            self.gl
                .uniform_4_i32(self.location(name).as_ref(), v[0], v[1], v[2], v[3])
        }
    }
    /// Set the uniform `name`, an `int[]`.
    pub fn set_i32_array(&self, name: &'static str, v: &[i32]) {
        unsafe { self.gl.uniform_1_i32_slice(self.location(name).as_ref(), v) }
    }
    /// Set the uniform `name`, a `float[]`.
    pub fn set_f32_array(&self, name: &'static str, v: &[f32]) {
        unsafe { self.gl.uniform_1_f32_slice(self.location(name).as_ref(), v) }
    }
    /// Set the uniform `name`, an `ivec2[]` (two ints each).
    pub fn set_ivec2_array(&self, name: &'static str, v: &[i32]) {
        unsafe { self.gl.uniform_2_i32_slice(self.location(name).as_ref(), v) }
    }
    /// Set the uniform `name`, an `ivec4[]` (four ints each).
    pub fn set_ivec4_array(&self, name: &'static str, v: &[i32]) {
        unsafe { self.gl.uniform_4_i32_slice(self.location(name).as_ref(), v) }
    }
    /// Set the uniform `name`, a `mat4[]` (column-major, 16 floats each).
    pub fn set_mat4_array(&self, name: &'static str, m: &[f32]) {
        unsafe {
            self.gl
                .uniform_matrix_4_f32_slice(self.location(name).as_ref(), false, m)
        }
    }
    /// Set the uniform `name`, a `vec3[]` (three floats each).
    pub fn set_vec3_array(&self, name: &'static str, v: &[f32]) {
        unsafe { self.gl.uniform_3_f32_slice(self.location(name).as_ref(), v) }
    }
    /// Set the uniform `name`, a `mat3[]` (column-major, 9 floats each).
    pub fn set_mat3_array(&self, name: &'static str, m: &[f32]) {
        unsafe {
            self.gl
                .uniform_matrix_3_f32_slice(self.location(name).as_ref(), false, m)
        }
    }
    /// Set the uniform `name`, a `mat4` (column-major).
    pub fn set_mat4(&self, name: &'static str, m: &[f32; 16]) {
        unsafe {
            self.gl
                .uniform_matrix_4_f32_slice(self.location(name).as_ref(), false, m)
        }
    }
}

impl Drop for Program {
    fn drop(&mut self) {
        unsafe { self.gl.delete_program(self.raw) }
    }
}
