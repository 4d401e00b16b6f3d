//! LZF decompression, for PCD's `binary_compressed` data (PCL compresses with liblzf).

use super::Fault;

/// LZF decompression (liblzf's `lzf_d.c`): a control byte below 32 starts a run of `ctrl + 1`
/// literal bytes; otherwise its top 3 bits are a length (7 = read one more length byte) and a
/// back-reference copies `length + 2` bytes from `((ctrl & 31) << 8) + next byte + 1` back.
/// The output must be exactly `expected` bytes.
pub(crate) fn lzf_decompress(input: &[u8], expected: usize) -> Result<Vec<u8>, Fault> {
    // A back-reference of at most 3 input bytes makes at most 264 output bytes.
    if expected > input.len().saturating_mul(88) {
        return Err(Fault::bare(format!(
            "{} compressed bytes cannot unpack to {expected}",
            input.len()
        )));
    }
    let corrupt = |what: &str| Fault::bare(format!("corrupt LZF data: {what}"));
    let mut out = Vec::with_capacity(expected);
    let mut bytes = input.iter().copied();
    while let Some(ctrl) = bytes.next() {
        if ctrl < 32 {
            let run = usize::from(ctrl) + 1;
            let before = out.len();
            out.extend(bytes.by_ref().take(run));
            if out.len() - before != run {
                return Err(corrupt("literal run past the end of input"));
            }
        } else {
            let mut len = usize::from(ctrl >> 5);
            if len == 7 {
                len += usize::from(bytes.next().ok_or_else(|| corrupt("missing length byte"))?);
            }
            len += 2;
            let low = bytes.next().ok_or_else(|| corrupt("missing offset byte"))?;
            let back = (usize::from(ctrl & 31) << 8) + usize::from(low) + 1;
            let from = out
                .len()
                .checked_sub(back)
                .ok_or_else(|| corrupt("back-reference before the start"))?;
            for k in 0..len {
                out.push(out[from + k]);
            }
        }
        if out.len() > expected {
            return Err(corrupt("more output than declared"));
        }
    }
    if out.len() != expected {
        return Err(corrupt(&format!(
            "{} bytes out, {expected} declared",
            out.len()
        )));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lzf_literal_and_overlapping_back_reference() {
        // "abc" as a literal run, then 6 bytes copied from 3 back (overlapping): "abcabcabc".
        let packed = [2, b'a', b'b', b'c', 0x80, 2];
        assert_eq!(lzf_decompress(&packed, 9).unwrap(), b"abcabcabc");
        // Long form: length field 7 + extra 3 = 10, + 2 = 12 bytes of 'x' from 1 back.
        let packed = [0, b'x', 0xE0, 3, 0];
        assert_eq!(lzf_decompress(&packed, 13).unwrap(), vec![b'x'; 13]);
        assert!(lzf_decompress(&packed, 12).is_err());
        assert!(lzf_decompress(&[0x20, 5], 3).is_err()); // reference before start
        assert!(lzf_decompress(&[4, 1, 2], 5).is_err()); // literal past the end
        assert!(lzf_decompress(&[0], usize::MAX).is_err());
    }
}
