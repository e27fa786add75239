//! `memcpy` and `memmove` for the static musl build (x86-64). musl's own
//! copy bytes one at a time up to an 8-byte boundary, then with
//! `rep movsq`: slow for the short copies the writers make for every
//! number (a number's digits appended to a line), where glibc's take a few
//! vector moves. These take one to four overlapping moves up to 64 bytes,
//! and `rep movsb` beyond (fast on every x86-64 since Ivy Bridge).
//!
//! Every move reads all its bytes before it writes any, so the short
//! copies are also right for overlapping ranges (`memmove`). Nothing here
//! may call `memcpy` itself: only fixed-size unaligned loads and stores,
//! which the compiler emits as moves, `rep movsb`, and a backwards loop of
//! volatile moves (which the compiler cannot turn into a `memmove` call).
//!
//! Compiled on every x86-64 build, so that the tests check them; only the
//! musl build exports them under the C library's names.

// Elsewhere only the tests call them.
#![cfg_attr(not(target_env = "musl"), allow(dead_code))]

use std::arch::asm;

/// Copies the first and the last `size_of::<T>()` bytes of `n` (between
/// one and two such sizes, so they overlap or meet), both read before
/// either is written.
#[inline(always)]
unsafe fn ends<T>(d: *mut u8, s: *const u8, n: usize) {
    let k = n - std::mem::size_of::<T>();
    let (a, b) = (
        (s as *const T).read_unaligned(),
        (s.add(k) as *const T).read_unaligned(),
    );
    (d as *mut T).write_unaligned(a);
    (d.add(k) as *mut T).write_unaligned(b);
}

/// Copies `n ≤ 64` bytes from `s` to `d`, every byte read before any is written.
#[inline(always)]
unsafe fn short(d: *mut u8, s: *const u8, n: usize) {
    match n {
        32.. => ends::<[u128; 2]>(d, s, n),
        16.. => ends::<u128>(d, s, n),
        8.. => ends::<u64>(d, s, n),
        4.. => ends::<u32>(d, s, n),
        2.. => ends::<u16>(d, s, n),
        1 => *d = *s,
        0 => {}
    }
}

/// Copies `n` bytes forwards with `rep movsb`.
#[inline(always)]
unsafe fn forwards(d: *mut u8, s: *const u8, n: usize) {
    asm!("rep movsb", inout("rcx") n => _, inout("rdi") d => _, inout("rsi") s => _, options(nostack, preserves_flags));
}

/// The C library's `memcpy`.
#[cfg_attr(target_env = "musl", no_mangle)]
pub unsafe extern "C" fn memcpy(d: *mut u8, s: *const u8, n: usize) -> *mut u8 {
    if n <= 64 {
        short(d, s, n);
    } else {
        forwards(d, s, n);
    }
    d
}

/// The C library's `memmove`.
#[cfg_attr(target_env = "musl", no_mangle)]
pub unsafe extern "C" fn memmove(d: *mut u8, s: *const u8, n: usize) -> *mut u8 {
    if n <= 64 {
        short(d, s, n);
    } else if (d as usize).wrapping_sub(s as usize) >= n {
        // `d` before `s`, or after its end: forwards is right.
        forwards(d, s, n);
    } else {
        // `d` inside `s..s + n`: 16 bytes at a time from the end, each
        // chunk read before it is written and above what is still to be
        // read, then the first `n % 16` bytes.
        let mut k = n;
        while k >= 16 {
            k -= 16;
            let a = std::ptr::read_volatile(s.add(k) as *const [u8; 16]);
            std::ptr::write_volatile(d.add(k) as *mut [u8; 16], a);
        }
        short(d, s, k);
    }
    d
}

#[cfg(test)]
mod tests {
    /// Both copy every length from 0 to 300 bytes right, at every
    /// alignment, and `memmove` every overlap, either way.
    #[test]
    fn copies_are_right() {
        let src: Vec<u8> = (0..400u32).map(|i| (i * 7 + 3) as u8).collect();
        for n in 0..300 {
            for off in 0..8 {
                let mut dst = vec![0u8; 400];
                // SAFETY: both ranges lie inside their vectors.
                unsafe { super::memcpy(dst.as_mut_ptr().add(off), src.as_ptr().add(off), n) };
                assert_eq!(&dst[off..off + n], &src[off..off + n], "memcpy {n} at {off}");
                assert!(
                    dst[..off].iter().chain(&dst[off + n..]).all(|&b| b == 0),
                    "memcpy {n} wrote outside"
                );
                for shift in [-40i64, -17, -16, -1, 1, 15, 16, 17, 40] {
                    let (from, to) = (50usize, (50 + shift) as usize);
                    let mut buf = src.clone();
                    let mut expected = src.clone();
                    expected.copy_within(from..from + n, to);
                    // SAFETY: both ranges lie inside the vector.
                    unsafe { super::memmove(buf.as_mut_ptr().add(to), buf.as_ptr().add(from), n) };
                    assert_eq!(buf, expected, "memmove {n} by {shift}");
                }
            }
        }
    }
}
