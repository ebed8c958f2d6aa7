//! Records and constants declared once, in Rust, with their GLSL text derived from the
//! declaration: [`gpu_record!`](crate::gpu_record) makes a `#[repr(C)]` struct and its std430 GLSL twin,
//! [`glsl_consts!`](crate::glsl_consts) makes `pub const`s and their GLSL `const`s. The GLSL header that collects
//! them (`shader_interface::glsl_header`) is written at build time by crates/vk/build.rs, so a
//! kernel can only see the layout that the host writes.
//!
//! A record's Rust offsets are checked against the std430 rules at compile time (GLSL 4.60
//! specification, section 7.6.2.2, "Standard Uniform Block Layout", with the std430 changes:
//! arrays and structs are not rounded up to 16 bytes), and tests/suite/layout.rs checks every
//! record of [`crate::shader_interface::records`] against the offsets glslang gives it.

use std::fmt::Write as _;

/// A Rust field type with a GLSL twin whose std430 layout has the same bytes.
pub trait GlslType {
    /// std430 base alignment, bytes.
    const ALIGN: usize;
    /// std430 size, bytes (a vec3 is 12: the next scalar may sit in its fourth word).
    const SIZE: usize;
    /// The GLSL declaration of a member `name` of this type, e.g. `vec3 pos` or
    /// `RestirPass passes[6]`.
    fn glsl_member(name: &str) -> String;
}

macro_rules! glsl_scalar_types {
    ($($rust:ty => $glsl:literal, $align:literal, $size:literal;)*) => {
        $(impl GlslType for $rust {
            const ALIGN: usize = $align;
            const SIZE: usize = $size;
            fn glsl_member(name: &str) -> String {
                format!(concat!($glsl, " {}"), name)
            }
        })*
    };
}

glsl_scalar_types! {
    f32 => "float", 4, 4;
    u32 => "uint", 4, 4;
    i32 => "int", 4, 4;
    [f32; 2] => "vec2", 8, 8;
    [f32; 3] => "vec3", 16, 12;
    [f32; 4] => "vec4", 16, 16;
    [u32; 2] => "uvec2", 8, 8;
    [u32; 3] => "uvec3", 16, 12;
    [u32; 4] => "uvec4", 16, 16;
}

/// `vec4 name[N]`: std430 gives an array of vec4 a 16-byte stride.
impl<const N: usize> GlslType for [[f32; 4]; N] {
    const ALIGN: usize = 16;
    const SIZE: usize = 16 * N;
    fn glsl_member(name: &str) -> String {
        format!("vec4 {name}[{N}]")
    }
}

/// `offset` rounded up to a multiple of `align` (a power of two).
pub const fn round_up(offset: usize, align: usize) -> usize {
    (offset + align - 1) & !(align - 1)
}

/// How GLSL declares a record.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum GlslDeclaration {
    /// `struct Name { ... };`, for records stored in arrays or nested in others.
    Struct,
    /// `#define NAME_FIELDS ...`, the member list of a buffer block named `Name` (a binding that
    /// holds one record, such as `FrameParams`): the block keeps the record's name, which is the
    /// binding's name in `shader_interface`.
    BlockFields,
}

/// One member of a record, as both sides see it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RecordField {
    /// The member's name, the same in Rust and GLSL.
    pub name: &'static str,
    /// Its GLSL declaration (`vec3 pos`).
    pub glsl: String,
    /// Its byte offset in the Rust struct, which the compile-time check makes the std430 one.
    pub offset: usize,
    /// The first sentence of its Rust doc comment, written beside the GLSL member.
    pub doc: String,
}

/// A record's name, layout and members: what the GLSL header and the layout test read.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RecordInfo {
    /// The struct's name in Rust and GLSL.
    pub name: &'static str,
    /// How GLSL declares it.
    pub declaration: GlslDeclaration,
    /// `size_of` the Rust struct, which is also its std430 array stride, bytes.
    pub size: usize,
    /// Its members in declaration order.
    pub fields: Vec<RecordField>,
}

/// A record shared with GLSL, implemented by [`gpu_record!`](crate::gpu_record).
pub trait GpuRecord: bytemuck::Pod {
    /// Its name, layout and members.
    fn info() -> RecordInfo;
}

/// The first sentence of a doc comment given as its lines, with rustdoc's link brackets
/// removed: the comment beside a generated GLSL member.
pub fn doc_summary(lines: &[&str]) -> String {
    let text = lines.iter().map(|l| l.trim()).collect::<Vec<_>>().join(" ");
    let sentence = match text.find(". ") {
        Some(end) => &text[..=end],
        None => text.as_str(),
    };
    sentence.replace("[`", "`").replace("`]", "`")
}

/// `CamelCase` to `CAMEL_CASE`, digits kept with their word (`Surfaces0` to `SURFACES0`).
pub fn upper_snake(name: &str) -> String {
    let mut out = String::with_capacity(name.len() + 4);
    for (i, c) in name.chars().enumerate() {
        if c.is_ascii_uppercase() && i > 0 {
            out.push('_');
        }
        out.push(c.to_ascii_uppercase());
    }
    out
}

impl RecordInfo {
    /// The record's GLSL text: a struct, or the `NAME_FIELDS` macro of a block.
    pub fn glsl(&self) -> String {
        let mut out = String::new();
        match self.declaration {
            GlslDeclaration::Struct => {
                writeln!(out, "struct {} {{", self.name).expect("string write");
                for f in &self.fields {
                    let member = format!("    {};", f.glsl);
                    if f.doc.is_empty() {
                        writeln!(out, "{member}").expect("string write");
                    } else {
                        writeln!(out, "{member:<36} // {}", f.doc).expect("string write");
                    }
                }
                out.push_str("};\n");
            }
            GlslDeclaration::BlockFields => {
                // One line: a `//` comment inside a macro body would swallow what follows it.
                write!(out, "#define {}_FIELDS", upper_snake(self.name)).expect("string write");
                for f in &self.fields {
                    write!(out, " {};", f.glsl).expect("string write");
                }
                out.push('\n');
            }
        }
        out
    }
}

/// Declares a `#[repr(C)]` record shared with GLSL: the struct as written (every field `pub`,
/// documented), its [`GpuRecord`] and [`GlslType`] implementations, and a compile-time check
/// that each field's Rust offset is its std430 offset and the size its std430 array stride.
/// The first token says how GLSL declares it: `struct` ([`GlslDeclaration::Struct`]) or
/// `block` ([`GlslDeclaration::BlockFields`]).
#[macro_export]
macro_rules! gpu_record {
    (@declaration struct) => { $crate::glsl_record::GlslDeclaration::Struct };
    (@declaration block) => { $crate::glsl_record::GlslDeclaration::BlockFields };
    (@is_struct struct) => { true };
    (@is_struct block) => { false };
    ($kind:ident;
     $(#[$meta:meta])*
     pub struct $name:ident {
        $($(#[doc = $doc:literal])* pub $field:ident : $ty:ty,)*
     }
    ) => {
        $(#[$meta])*
        #[repr(C)]
        pub struct $name {
            $($(#[doc = $doc])* pub $field: $ty,)*
        }

        impl $crate::glsl_record::GlslType for $name {
            const ALIGN: usize = {
                let mut align = 1;
                $(if <$ty as $crate::glsl_record::GlslType>::ALIGN > align {
                    align = <$ty as $crate::glsl_record::GlslType>::ALIGN;
                })*
                align
            };
            const SIZE: usize = ::std::mem::size_of::<$name>();
            fn glsl_member(name: &str) -> String {
                format!("{} {}", stringify!($name), name)
            }
        }

        impl<const N: usize> $crate::glsl_record::GlslType for [$name; N] {
            const ALIGN: usize = <$name as $crate::glsl_record::GlslType>::ALIGN;
            const SIZE: usize = N * ::std::mem::size_of::<$name>();
            fn glsl_member(name: &str) -> String {
                format!("{} {}[{}]", stringify!($name), name, N)
            }
        }

        const _: () = {
            use $crate::glsl_record::{round_up, GlslType};
            let mut offset = 0usize;
            $(
                offset = round_up(offset, <$ty as GlslType>::ALIGN);
                assert!(
                    offset == ::std::mem::offset_of!($name, $field),
                    concat!(
                        stringify!($name), "::", stringify!($field),
                        ": the Rust offset is not the std430 offset (std430 starts a vec3/[f32; 3] or vec4 on 16 bytes, a vec2 on 8: pad before it with u32 fields)"
                    )
                );
                offset += <$ty as GlslType>::SIZE;
            )*
            // A block is never an array element: only a struct's size must be its stride.
            assert!(
                !$crate::gpu_record!(@is_struct $kind)
                    || round_up(offset, <$name as GlslType>::ALIGN) == ::std::mem::size_of::<$name>(),
                concat!(stringify!($name), ": the Rust size is not the std430 array stride")
            );
        };

        impl $crate::glsl_record::GpuRecord for $name {
            fn info() -> $crate::glsl_record::RecordInfo {
                $crate::glsl_record::RecordInfo {
                    name: stringify!($name),
                    declaration: $crate::gpu_record!(@declaration $kind),
                    size: ::std::mem::size_of::<$name>(),
                    fields: vec![$($crate::glsl_record::RecordField {
                        name: stringify!($field),
                        glsl: <$ty as $crate::glsl_record::GlslType>::glsl_member(stringify!($field)),
                        offset: ::std::mem::offset_of!($name, $field),
                        doc: $crate::glsl_record::doc_summary(&[$($doc),*]),
                    }),*],
                }
            }
        }
    };
}

/// A constant's GLSL type and literal.
pub trait GlslConst: Copy {
    /// `const <type> NAME = <literal>;` for this value.
    fn glsl_const(self, name: &str) -> String;
}

impl GlslConst for u32 {
    fn glsl_const(self, name: &str) -> String {
        if self >= 0x1000_0000 {
            format!("const uint {name} = 0x{self:08x}u;")
        } else {
            format!("const uint {name} = {self}u;")
        }
    }
}

impl GlslConst for f32 {
    fn glsl_const(self, name: &str) -> String {
        // `{:?}` writes the shortest text that reads back as the same f32, always with a '.'
        // or an exponent, which GLSL parses as a float literal.
        format!("const float {name} = {self:?};")
    }
}

/// Declares `pub const`s shared with GLSL and `$list`, a function returning their GLSL
/// declarations in order (`const uint NAME = 1u;`), for the generated header.
#[macro_export]
macro_rules! glsl_consts {
    ($(#[$list_meta:meta])* fn $list:ident;
     $($(#[doc = $doc:literal])* pub const $name:ident : $ty:ty = $value:expr;)*) => {
        $($(#[doc = $doc])* pub const $name: $ty = $value;)*

        $(#[$list_meta])*
        pub fn $list() -> Vec<String> {
            vec![$($crate::glsl_record::GlslConst::glsl_const($name, stringify!($name))),*]
        }
    };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scalar_and_vector_layouts_follow_std430() {
        assert_eq!((<[f32; 3]>::ALIGN, <[f32; 3]>::SIZE), (16, 12));
        assert_eq!((<[[f32; 4]; 3]>::ALIGN, <[[f32; 4]; 3]>::SIZE), (16, 48));
        assert_eq!(<[f32; 3]>::glsl_member("pos"), "vec3 pos");
        assert_eq!(<[[f32; 4]; 3]>::glsl_member("uv"), "vec4 uv[3]");
        assert_eq!(round_up(12, 16), 16);
        assert_eq!(round_up(16, 16), 16);
    }

    #[test]
    fn constants_read_back_as_the_same_value() {
        assert_eq!(1e-3f32.glsl_const("A"), "const float A = 0.001;");
        assert_eq!((1.0f32 / 65536.0).glsl_const("B"), "const float B = 1.5258789e-5;");
        assert_eq!(u32::MAX.glsl_const("C"), "const uint C = 0xffffffffu;");
        assert_eq!(16u32.glsl_const("D"), "const uint D = 16u;");
    }

    #[test]
    fn doc_summary_is_the_first_sentence_without_link_brackets() {
        assert_eq!(doc_summary(&[" Bit set: [`A`], [`B`]. More", " text."]), "Bit set: `A`, `B`.");
        assert_eq!(doc_summary(&[" One line", " and its rest"]), "One line and its rest");
    }

    #[test]
    fn upper_snake_keeps_digits_with_their_word() {
        assert_eq!(upper_snake("ReservoirHeads0"), "RESERVOIR_HEADS0");
        assert_eq!(upper_snake("AccumSq"), "ACCUM_SQ");
    }
}
