//! A QEMU TCG plugin that counts the guest instructions of every call of chosen functions of
//! a Thumb (Cortex-M) firmware: repeatable cost figures, since QEMU emulates no cycle counter.
//!
//! ```text
//! qemu-system-arm … -plugin libqemu_insn_count.so,fn=NAME@0xADDR,fn=…,out=PATH
//! ```
//!
//! * `fn=NAME@0xADDR`: a function to measure, by its entry address (the Thumb bit may be set).
//! * `out=PATH`: where the calls go when QEMU exits, one line each in the order they returned:
//!   `call NAME INCLUSIVE SELF`, where INCLUSIVE counts every instruction from the `bl` up to
//!   the return, callees included, and SELF leaves out the calls of other measured functions
//!   made inside it. Calls still open at exit are listed as `open NAME INCLUSIVE`.
//!
//! How: every instruction adds one to a counter inline (exact, not per translation block).
//! A call is a `bl` whose target is a measured entry: the plugin notes the counter and the
//! return address (the instruction after the `bl`). A return lands on a translation block's
//! first instruction, so only those are checked against the innermost open call. A `bl` in an
//! IT block (Thumb-2) runs the callback even when its condition fails: such a call counts
//! only once the block at its entry has run, and is dropped, unrecorded, when the block after
//! the `bl` runs first. A function
//! reached any other way (`blx` through a pointer, a tail call) is not seen; the firmware that
//! is measured calls its measured functions with `bl`, through wrappers where need be.
//!
//! Built for the plugin API of QEMU 7.2 (Debian 12), version 1.

use std::collections::HashMap;
use std::ffi::{c_char, c_int, c_uint, c_void, CStr};
use std::fmt::Write as _;
use std::sync::Mutex;

use qemu_plugin_sys::*;

/// The API version this plugin is built for; QEMU refuses a plugin without it.
#[no_mangle]
pub static qemu_plugin_version: c_int = QEMU_PLUGIN_VERSION as c_int;

/// Instructions executed so far, bumped by inline TCG ops (single vCPU).
static mut COUNT: u64 = 0;

struct Open {
    function: usize,
    /// The function's entry; until its block runs, the `bl` may have been skipped.
    entry: u64,
    entered: bool,
    return_addr: u64,
    start: u64,
    /// Inclusive counts of measured calls made inside this one.
    nested: u64,
}

#[derive(Default)]
struct State {
    names: Vec<String>,
    entries: HashMap<u64, usize>,
    out: String,
    open: Vec<Open>,
    lines: String,
}

static STATE: Mutex<Option<State>> = Mutex::new(None);

fn count() -> u64 {
    // Note(unsafe): COUNT is written only by TCG inline ops of the one vCPU thread, which is
    // the thread calling this (callbacks run on it, between instructions).
    unsafe { core::ptr::addr_of!(COUNT).read_volatile() }
}

/// Target of a 32-bit Thumb `bl` at `pc` made of halfwords `h1`, `h2`; `None` if it is not one.
fn bl_target(pc: u64, h1: u16, h2: u16) -> Option<u64> {
    if h1 & 0xF800 != 0xF000 || h2 & 0xD000 != 0xD000 {
        return None;
    }
    let s = ((h1 >> 10) & 1) as u32;
    let imm10 = (h1 & 0x3FF) as u32;
    let j1 = ((h2 >> 13) & 1) as u32;
    let j2 = ((h2 >> 11) & 1) as u32;
    let imm11 = (h2 & 0x7FF) as u32;
    let i1 = !(j1 ^ s) & 1;
    let i2 = !(j2 ^ s) & 1;
    let imm = (s << 24) | (i1 << 23) | (i2 << 22) | (imm10 << 12) | (imm11 << 1);
    let offset = ((imm << 7) as i32) >> 7; // sign-extend 25 bits
    Some(pc.wrapping_add(4).wrapping_add(offset as i64 as u64) & 0xFFFF_FFFF)
}

/// What a callback needs to know about its instruction; leaked, like QEMU's translations.
#[derive(Clone, Copy)]
struct Call {
    function: usize,
    entry: u64,
    return_addr: u64,
}

impl State {
    /// A `bl` to a measured function ran (its condition may have failed) at count `now`.
    fn call(&mut self, call: Call, now: u64) {
        self.open.push(Open {
            function: call.function,
            entry: call.entry,
            entered: false,
            return_addr: call.return_addr,
            start: now,
            nested: 0,
        });
    }

    /// A translation block starting at `pc` runs, at count `now`.
    fn block_start(&mut self, pc: u64, now: u64) {
        if let Some(top) = self.open.last_mut() {
            if !top.entered {
                if pc == top.entry {
                    top.entered = true;
                    return;
                }
                if pc == top.return_addr {
                    // A conditional `bl` whose condition failed: no call.
                    self.open.pop();
                    return;
                }
            }
        }
        // Calls whose return was never seen (left by an exception, say) are dropped up to the
        // one this address returns from.
        let Some(depth) = self.open.iter().rposition(|o| o.return_addr == pc) else {
            return;
        };
        while self.open.len() > depth {
            let Some(done) = self.open.pop() else { break };
            let inclusive = now - done.start;
            let own = inclusive - done.nested;
            if self.open.len() == depth {
                let _ = writeln!(
                    self.lines,
                    "call {} {inclusive} {own}",
                    self.names[done.function]
                );
            } else {
                let _ = writeln!(self.lines, "lost {}", self.names[done.function]);
            }
            if let Some(parent) = self.open.last_mut() {
                parent.nested += inclusive;
            }
        }
    }
}

unsafe extern "C" fn on_call(_vcpu: c_uint, udata: *mut c_void) {
    // Note(unsafe): udata is a leaked `Call` made at translation, never freed.
    let call = unsafe { *(udata as *const Call) };
    let now = count();
    if let Some(state) = STATE.lock().unwrap_or_else(|e| e.into_inner()).as_mut() {
        state.call(call, now);
    }
}

unsafe extern "C" fn on_block_start(_vcpu: c_uint, udata: *mut c_void) {
    let pc = udata as u64;
    let now = count();
    if let Some(state) = STATE.lock().unwrap_or_else(|e| e.into_inner()).as_mut() {
        state.block_start(pc, now);
    }
}

unsafe extern "C" fn on_translate(_id: qemu_plugin_id_t, tb: *mut qemu_plugin_tb) {
    let guard = STATE.lock().unwrap_or_else(|e| e.into_inner());
    let Some(state) = guard.as_ref() else { return };
    // Note(unsafe): `tb` and its instructions are valid for the duration of this callback,
    // which is when QEMU allows registering their callbacks.
    unsafe {
        let n = qemu_plugin_tb_n_insns(tb);
        for i in 0..n {
            let insn = qemu_plugin_tb_get_insn(tb, i);
            qemu_plugin_register_vcpu_insn_exec_inline(
                insn,
                qemu_plugin_op::QEMU_PLUGIN_INLINE_ADD_U64,
                core::ptr::addr_of_mut!(COUNT) as *mut c_void,
                1,
            );
            let pc = qemu_plugin_insn_vaddr(insn);
            if i == 0 {
                qemu_plugin_register_vcpu_insn_exec_cb(
                    insn,
                    Some(on_block_start),
                    qemu_plugin_cb_flags::QEMU_PLUGIN_CB_NO_REGS,
                    pc as *mut c_void,
                );
            }
            if qemu_plugin_insn_size(insn) == 4 {
                let bytes =
                    core::slice::from_raw_parts(qemu_plugin_insn_data(insn) as *const u8, 4);
                let h1 = u16::from_le_bytes([bytes[0], bytes[1]]);
                let h2 = u16::from_le_bytes([bytes[2], bytes[3]]);
                let target = bl_target(pc, h1, h2);
                if let Some((entry, &function)) =
                    target.and_then(|t| state.entries.get(&t).map(|f| (t, f)))
                {
                    let call = Box::leak(Box::new(Call {
                        function,
                        entry,
                        return_addr: pc + 4,
                    }));
                    qemu_plugin_register_vcpu_insn_exec_cb(
                        insn,
                        Some(on_call),
                        qemu_plugin_cb_flags::QEMU_PLUGIN_CB_NO_REGS,
                        call as *mut Call as *mut c_void,
                    );
                }
            }
        }
    }
}

unsafe extern "C" fn on_exit(_id: qemu_plugin_id_t, _udata: *mut c_void) {
    let now = count();
    let mut guard = STATE.lock().unwrap_or_else(|e| e.into_inner());
    let Some(state) = guard.as_mut() else { return };
    let mut text = std::mem::take(&mut state.lines);
    for o in &state.open {
        let _ = writeln!(text, "open {} {}", state.names[o.function], now - o.start);
    }
    let _ = writeln!(text, "total {now}");
    if let Err(e) = std::fs::write(&state.out, text) {
        eprintln!("qemu-insn-count: cannot write {}: {e}", state.out);
    }
}

fn parse_args(args: &[String]) -> Result<State, String> {
    let mut state = State::default();
    for arg in args {
        if let Some(v) = arg.strip_prefix("fn=") {
            let (name, addr) = v
                .split_once('@')
                .ok_or_else(|| format!("`{arg}`: expected fn=NAME@0xADDR"))?;
            let addr = u64::from_str_radix(addr.trim_start_matches("0x"), 16)
                .map_err(|e| format!("`{arg}`: address: {e}"))?;
            state.entries.insert(addr & !1, state.names.len());
            state.names.push(name.to_string());
        } else if let Some(v) = arg.strip_prefix("out=") {
            state.out = v.to_string();
        } else {
            return Err(format!(
                "unknown argument `{arg}` (fn=NAME@0xADDR, out=PATH)"
            ));
        }
    }
    if state.out.is_empty() {
        return Err("missing out=PATH".into());
    }
    Ok(state)
}

/// Entry point QEMU calls on loading the plugin.
///
/// # Safety
/// Called by QEMU with `argc` valid C strings in `argv`.
#[no_mangle]
pub unsafe extern "C" fn qemu_plugin_install(
    id: qemu_plugin_id_t,
    _info: *const qemu_info_t,
    argc: c_int,
    argv: *mut *mut c_char,
) -> c_int {
    let args: Vec<String> = (0..argc.max(0) as usize)
        // Note(unsafe): QEMU passes argc NUL-terminated strings.
        .map(|i| {
            unsafe { CStr::from_ptr(*argv.add(i)) }
                .to_string_lossy()
                .into_owned()
        })
        .collect();
    match parse_args(&args) {
        Ok(state) => {
            *STATE.lock().unwrap_or_else(|e| e.into_inner()) = Some(state);
            // Note(unsafe): registration calls with this plugin's id and static callbacks.
            unsafe {
                qemu_plugin_register_vcpu_tb_trans_cb(id, Some(on_translate));
                qemu_plugin_register_atexit_cb(id, Some(on_exit), core::ptr::null_mut());
            }
            0
        }
        Err(e) => {
            eprintln!("qemu-insn-count: {e}");
            -1
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{bl_target, Call, State};

    fn state() -> State {
        State {
            names: vec!["outer".into(), "inner".into()],
            ..State::default()
        }
    }

    const OUTER: Call = Call {
        function: 0,
        entry: 0x100,
        return_addr: 0x54,
    };
    const INNER: Call = Call {
        function: 1,
        entry: 0x200,
        return_addr: 0x130,
    };

    #[test]
    fn a_call_counts_from_its_bl_to_its_return_and_nested_calls_leave_own() {
        let mut s = state();
        s.call(OUTER, 10);
        s.block_start(0x100, 11);
        s.call(INNER, 20);
        s.block_start(0x200, 21);
        s.block_start(0x130, 45);
        s.block_start(0x54, 60);
        assert_eq!(s.lines, "call inner 25 25\ncall outer 50 25\n");
        assert!(s.open.is_empty());
    }

    #[test]
    fn a_skipped_conditional_bl_is_no_call() {
        let mut s = state();
        s.call(OUTER, 10);
        s.block_start(0x100, 11);
        // `blpl inner` with the condition failed: the block after it runs next.
        s.call(INNER, 20);
        s.block_start(0x130, 21);
        s.block_start(0x54, 30);
        assert_eq!(s.lines, "call outer 20 20\n");
        assert!(s.open.is_empty());
    }

    #[test]
    fn decodes_bl_both_ways() {
        // `bl` forward by 0x100 at 0x1000: target 0x1104.
        assert_eq!(bl_target(0x1000, 0xF000, 0xF880), Some(0x1104));
        // `bl` backward by 4 at 0x2000: offset −4 → 0x2000.
        assert_eq!(bl_target(0x2000, 0xF7FF, 0xFFFE), Some(0x2000));
        // A `b.w` (bit 12 set, bit 14 clear) is not a call.
        assert_eq!(bl_target(0x1000, 0xF000, 0xB880), None);
    }
}
