//! The descriptor bindings a SPIR-V module declares, read from its decorations, and the check
//! of a kernel's declared layout against them. Only what the kernels use is understood:
//! buffer blocks, as uniform (`Uniform` + `Block`) or storage buffers
//! (`StorageBuffer`, or `Uniform` + `BufferBlock`). The opcodes and enumerants are those of
//! the SPIR-V 1.5 specification, section 3.

use std::collections::HashMap;

use super::Binding;

const OP_NAME: u32 = 5;
const OP_TYPE_POINTER: u32 = 32;
const OP_VARIABLE: u32 = 59;
const OP_DECORATE: u32 = 71;
const DECORATION_BLOCK: u32 = 2;
const DECORATION_BUFFER_BLOCK: u32 = 3;
const DECORATION_BINDING: u32 = 33;
const DECORATION_DESCRIPTOR_SET: u32 = 34;
const STORAGE_CLASS_UNIFORM: u32 = 2;
const STORAGE_CLASS_STORAGE_BUFFER: u32 = 12;

/// One buffer binding of a SPIR-V module.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ReflectedBinding {
    /// Descriptor set number (0 when the module gives none).
    pub set: u32,
    /// Binding number within the set.
    pub binding: u32,
    /// The block's type name (the GLSL block name), empty without debug names.
    pub block: String,
    /// Uniform or storage buffer (a `BufferBlock`-decorated uniform counts as storage).
    pub kind: Binding,
    /// Some instruction of the module's functions loads from the buffer (or asks its array's
    /// length, or passes a pointer into it to a function, which counts as both).
    pub reads: bool,
    /// Some instruction of the module's functions stores to the buffer (or runs an atomic on it).
    pub writes: bool,
}

const OP_FUNCTION: u32 = 54;
const OP_FUNCTION_CALL: u32 = 57;
const OP_LOAD: u32 = 61;
const OP_STORE: u32 = 62;
const OP_COPY_MEMORY: u32 = 63;
const OP_ACCESS_CHAIN: u32 = 65;
const OP_IN_BOUNDS_ACCESS_CHAIN: u32 = 66;
const OP_PTR_ACCESS_CHAIN: u32 = 67;
const OP_ARRAY_LENGTH: u32 = 68;
const OP_IN_BOUNDS_PTR_ACCESS_CHAIN: u32 = 70;
const OP_COPY_OBJECT: u32 = 83;
const OP_ATOMIC_LOAD: u32 = 227;
const OP_ATOMIC_STORE: u32 = 228;
const OP_ATOMIC_FIRST_READ_WRITE: u32 = 229; // OpAtomicExchange
const OP_ATOMIC_LAST_READ_WRITE: u32 = 242; // OpAtomicXor
const OP_ATOMIC_FADD_EXT: u32 = 6035;

/// The instructions of a SPIR-V module (its words, the 5-word header included) as (opcode,
/// operands), in order; a malformed instruction ends them rather than panics.
pub fn spirv_instructions(spirv: &[u32]) -> impl Iterator<Item = (u32, &[u32])> {
    let mut i = 5;
    std::iter::from_fn(move || {
        let word = *spirv.get(i)?;
        let (count, op) = ((word >> 16) as usize, word & 0xffff);
        if count == 0 || i + count > spirv.len() {
            return None;
        }
        let args = &spirv[i + 1..i + count];
        i += count;
        Some((op, args))
    })
}

/// Which variables the module's functions read and write: pointers derived by access chains
/// (and copies) are traced to their variable, then loads, stores, atomics, array lengths and
/// pointer arguments of calls mark it. The map holds only variables that were accessed.
fn variable_access(spirv: &[u32]) -> HashMap<u32, (bool, bool)> {
    let mut root: HashMap<u32, u32> = HashMap::new();
    let mut access: HashMap<u32, (bool, bool)> = HashMap::new();
    let mut in_functions = false;
    for (op, args) in spirv_instructions(spirv) {
        match op {
            OP_VARIABLE if args.len() >= 2 => {
                root.insert(args[1], args[1]);
            }
            OP_FUNCTION => in_functions = true,
            _ => {}
        }
        if !in_functions {
            continue;
        }
        let var = |id: u32| root.get(&id).copied();
        let mut mark = |id: u32, read: bool, write: bool| {
            if let Some(v) = var(id) {
                let e = access.entry(v).or_default();
                e.0 |= read;
                e.1 |= write;
            }
        };
        match op {
            OP_ACCESS_CHAIN | OP_IN_BOUNDS_ACCESS_CHAIN | OP_PTR_ACCESS_CHAIN | OP_IN_BOUNDS_PTR_ACCESS_CHAIN | OP_COPY_OBJECT
                if args.len() >= 3 =>
            {
                if let Some(v) = var(args[2]) {
                    root.insert(args[1], v);
                }
            }
            OP_LOAD | OP_ARRAY_LENGTH | OP_ATOMIC_LOAD if args.len() >= 3 => mark(args[2], true, false),
            OP_STORE | OP_ATOMIC_STORE if !args.is_empty() => mark(args[0], false, true),
            OP_COPY_MEMORY if args.len() >= 2 => {
                mark(args[0], false, true);
                mark(args[1], true, false);
            }
            OP_ATOMIC_FIRST_READ_WRITE..=OP_ATOMIC_LAST_READ_WRITE | OP_ATOMIC_FADD_EXT if args.len() >= 3 => mark(args[2], true, true),
            OP_FUNCTION_CALL if args.len() >= 3 => {
                for &a in &args[3..] {
                    mark(a, true, true);
                }
            }
            _ => {}
        }
    }
    access
}

fn spirv_string(words: &[u32]) -> String {
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).take_while(|&b| b != 0).collect();
    String::from_utf8_lossy(&bytes).into_owned()
}

/// The buffer bindings of `spirv` (a module's words, header included), sorted by set and
/// binding. Malformed instructions end the scan rather than panic.
pub fn reflect_bindings(spirv: &[u32]) -> Vec<ReflectedBinding> {
    let mut names = HashMap::new();
    let mut decorations: HashMap<(u32, u32), u32> = HashMap::new();
    let mut pointers = HashMap::new();
    let mut variables = Vec::new();
    for (op, args) in spirv_instructions(spirv) {
        match op {
            OP_NAME if !args.is_empty() => {
                names.insert(args[0], spirv_string(&args[1..]));
            }
            OP_DECORATE if args.len() >= 2 => {
                decorations.insert((args[0], args[1]), args.get(2).copied().unwrap_or(0));
            }
            OP_TYPE_POINTER if args.len() >= 3 => {
                pointers.insert(args[0], (args[1], args[2]));
            }
            OP_VARIABLE if args.len() >= 3 => variables.push((args[0], args[1], args[2])),
            _ => {}
        }
    }
    let mut out: Vec<(ReflectedBinding, u32)> = variables
        .into_iter()
        .filter_map(|(pointer, id, class)| {
            let binding = *decorations.get(&(id, DECORATION_BINDING))?;
            let set = decorations.get(&(id, DECORATION_DESCRIPTOR_SET)).copied().unwrap_or(0);
            let &(_, block) = pointers.get(&pointer)?;
            let kind = match class {
                STORAGE_CLASS_STORAGE_BUFFER => Binding::Storage,
                STORAGE_CLASS_UNIFORM if decorations.contains_key(&(block, DECORATION_BUFFER_BLOCK)) => Binding::Storage,
                STORAGE_CLASS_UNIFORM if decorations.contains_key(&(block, DECORATION_BLOCK)) => Binding::Uniform,
                _ => return None,
            };
            let binding = ReflectedBinding {
                set,
                binding,
                block: names.get(&block).cloned().unwrap_or_default(),
                kind,
                reads: false,
                writes: false,
            };
            Some((binding, id))
        })
        .collect();
    let access = variable_access(spirv);
    for (b, id) in out.iter_mut() {
        (b.reads, b.writes) = access.get(id).copied().unwrap_or_default();
    }
    let mut out: Vec<ReflectedBinding> = out.into_iter().map(|(b, _)| b).collect();
    out.sort_by_key(|b| (b.set, b.binding));
    out
}

/// Checks that every binding `spirv` accesses is in `layout` under the same set and number,
/// block name and descriptor kind. A binding of `layout` the module lacks is allowed, and so is
/// one the module declares but never reads or writes: it is not statically used (Vulkan 1.3,
/// "Static Use"), so a pipeline layout may leave it out. The error names the kernel, the
/// binding and both sides.
pub fn check_bindings(kernel: &str, spirv: &[u32], layout: &[super::BindingSlot]) -> Result<(), String> {
    for (i, slot) in layout.iter().enumerate() {
        if layout[..i]
            .iter()
            .any(|s| (s.set == slot.set && s.binding == slot.binding) || s.block == slot.block)
        {
            return Err(format!(
                "kernel {kernel}: the host layout declares binding {} ({}) of set {} twice",
                slot.binding, slot.block, slot.set
            ));
        }
    }
    for found in reflect_bindings(spirv).into_iter().filter(|b| b.reads || b.writes) {
        let Some(slot) = layout.iter().find(|s| s.set == found.set && s.binding == found.binding) else {
            return Err(format!(
                "kernel {kernel}: the shader declares binding {} ({}) of set {}, the host layout does not",
                found.binding, found.block, found.set
            ));
        };
        if slot.block != found.block || slot.kind != found.kind {
            return Err(format!(
                "kernel {kernel}: binding {} is {} ({:?}) in the shader but {} ({:?}) in the host layout (set {})",
                found.binding, found.block, found.kind, slot.block, slot.kind, found.set
            ));
        }
    }
    Ok(())
}
