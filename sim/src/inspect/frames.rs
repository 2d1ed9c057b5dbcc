//! Checks on an `.rrd` file that Rerun's decoder does not make.
//!
//! The decoder trusts the sizes a file states: a damaged message length
//! or uncompressed size makes it allocate whatever the damaged bytes say
//! (an abort, not an error), and Arrow's reader can panic on damaged
//! bytes. So every stated size is checked against the file first
//! ([`check`]), and the decoding runs in [`guarded`], which turns a panic
//! into an error.

use std::cell::Cell;
use std::io::{self, Read, Seek, SeekFrom};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::sync::Once;

use re_log_encoding::external::lz4_flex;
use re_protos::common::v1alpha1::Compression;
use re_protos::external::prost::Message as _;
use re_protos::log_msg::v1alpha1::ArrowMsg;
use rerun::external::arrow::ipc::root_as_message;

/// Bytes of a stream header: `RRF2`, the Rerun version, the options.
const RRD_HEADER: u64 = 12;
/// Bytes of a message header: the kind and the length (u64 each).
const MESSAGE_HEADER: u64 = 16;
/// Bytes of the stream footer after the end-of-stream message (one entry).
const RRD_FOOTER: u64 = 32;
/// The message kinds of Rerun 0.36: end of stream, store info, Arrow
/// data, blueprint activation.
const KIND_END: u64 = 0;
const KIND_ARROW: u64 = 2;
const KINDS: u64 = 4;
/// The most an LZ4 block expands: each byte of a block stands for at most
/// 255 bytes of output (a run-length byte), plus a small constant.
const LZ4_MAX_RATIO: u64 = 255;

/// Walks the messages of the file `len` bytes long that `reader` holds:
/// every stream header is one this decoder reads, every message kind is
/// known, every message fits in what is left of the file, and every Arrow
/// message states an uncompressed size its compressed bytes can have.
/// The error says what is wrong and at which byte.
pub(crate) fn check(reader: &mut (impl Read + Seek), len: u64) -> Result<(), String> {
    reader.seek(SeekFrom::Start(0)).map_err(|e| e.to_string())?;
    let mut at = 0u64;
    let mut payload = Vec::new();
    while at < len {
        rrd_header(reader, at, len)?;
        at += RRD_HEADER;
        loop {
            if len - at < MESSAGE_HEADER {
                return Err(format!(
                    "it is truncated: it ends at byte {len} inside a message header, or \
                     without the end of its stream"
                ));
            }
            let mut head = [0u8; MESSAGE_HEADER as usize];
            read_exact(reader, &mut head, at)?;
            let kind = u64::from_le_bytes(head[..8].try_into().expect("8 bytes"));
            let size = u64::from_le_bytes(head[8..].try_into().expect("8 bytes"));
            if kind >= KINDS {
                return Err(format!(
                    "it is corrupt: the message at byte {at} is of unknown kind {kind}"
                ));
            }
            let left = len - at - MESSAGE_HEADER;
            if size > left {
                return Err(format!(
                    "it is corrupt or truncated: the message at byte {at} says it is {size} \
                     bytes long, and {left} are left"
                ));
            }
            if kind == KIND_ARROW {
                payload.clear();
                payload.resize(size as usize, 0);
                read_exact(reader, &mut payload, at + MESSAGE_HEADER)?;
                arrow_message(&payload, at)?;
            } else {
                reader
                    .seek(SeekFrom::Current(size as i64))
                    .map_err(|e| e.to_string())?;
            }
            at += MESSAGE_HEADER + size;
            if kind == KIND_END {
                if len - at < RRD_FOOTER {
                    return Err(format!(
                        "it is truncated: it ends at byte {len} inside its stream footer"
                    ));
                }
                reader
                    .seek(SeekFrom::Start(at))
                    .map_err(|e| e.to_string())?;
                let mut footer = [0u8; RRD_FOOTER as usize];
                read_exact(reader, &mut footer, at)?;
                rrd_footer(&footer, at)?;
                at += RRD_FOOTER;
                break;
            }
        }
    }
    Ok(())
}

/// Checks the stream header at `at`: `RRF2`, options this decoder reads.
fn rrd_header(reader: &mut impl Read, at: u64, len: u64) -> Result<(), String> {
    if len - at < RRD_HEADER {
        return Err(format!(
            "it is corrupt: {} byte(s) after byte {at} are not a Rerun stream",
            len - at
        ));
    }
    let mut head = [0u8; RRD_HEADER as usize];
    read_exact(reader, &mut head, at)?;
    if &head[..4] != b"RRF2" {
        return Err(format!(
            "it is corrupt: the bytes at {at} are neither a message nor a Rerun stream"
        ));
    }
    match head[8..] {
        [0 | 1, 2, 0, 0] => Ok(()),
        _ => Err(format!(
            "it is corrupt: the stream at byte {at} has encoding options {:?}, which Rerun \
             never writes",
            &head[8..]
        )),
    }
}

/// Checks the stream footer at `at`: one entry (20 bytes: the span of
/// the RRD footer and its checksum), then `RRF2`, `FOOT` and the number of
/// entries, 1 (the decoder allocates as many as that number says).
fn rrd_footer(footer: &[u8; RRD_FOOTER as usize], at: u64) -> Result<(), String> {
    let entries = u32::from_le_bytes(footer[28..].try_into().expect("4 bytes"));
    if &footer[20..24] != b"RRF2" || &footer[24..28] != b"FOOT" || entries != 1 {
        return Err(format!(
            "it is corrupt: its stream footer at byte {at} is not `RRF2` `FOOT` with one entry"
        ));
    }
    Ok(())
}

/// Checks an Arrow message's stated uncompressed size against its bytes.
fn arrow_message(payload: &[u8], at: u64) -> Result<(), String> {
    let msg = ArrowMsg::decode(payload)
        .map_err(|e| format!("it is corrupt: the message at byte {at} does not decode ({e})"))?;
    // Uncompressed: the Arrow bytes as they are; LZ4: decompressed into as
    // many bytes as the message says.
    if msg.compression() != Compression::Lz4 {
        return ipc_stream(&msg.payload)
            .map_err(|why| format!("it is corrupt: the message at byte {at} {why}"));
    }
    let compressed = msg.payload.len() as u64;
    let most = compressed.saturating_mul(LZ4_MAX_RATIO).saturating_add(64);
    if msg.uncompressed_size > most {
        return Err(format!(
            "it is corrupt: the message at byte {at} says its {compressed} compressed bytes \
             hold {}, more than they can",
            msg.uncompressed_size
        ));
    }
    let mut ipc = vec![0u8; msg.uncompressed_size as usize];
    let got = lz4_flex::block::decompress_into(&msg.payload, &mut ipc).map_err(|e| {
        format!("it is corrupt: the message at byte {at} does not decompress ({e})")
    })?;
    ipc.truncate(got);
    ipc_stream(&ipc).map_err(|why| format!("it is corrupt: the message at byte {at} {why}"))
}

/// Checks the sizes an Arrow IPC stream states (each message's metadata
/// and body) against its bytes: Arrow's reader allocates what they say.
fn ipc_stream(data: &[u8]) -> Result<(), String> {
    let mut pos = 0usize;
    let word = |pos: usize| -> Option<[u8; 4]> { data.get(pos..pos + 4)?.try_into().ok() };
    loop {
        let Some(mut len) = word(pos) else {
            return Ok(());
        };
        pos += 4;
        if len == [0xff; 4] {
            len = word(pos).ok_or("ends inside an Arrow message length")?;
            pos += 4;
        }
        let meta = i32::from_le_bytes(len);
        if meta == 0 {
            return Ok(());
        }
        let left = data.len() - pos;
        let meta = usize::try_from(meta)
            .ok()
            .filter(|&m| m <= left)
            .ok_or_else(|| format!("has Arrow metadata of {meta} bytes, and {left} are left"))?;
        let message = root_as_message(&data[pos..pos + meta])
            .map_err(|e| format!("has Arrow metadata that does not parse ({e})"))?;
        pos += meta;
        let left = data.len() - pos;
        let body = message.bodyLength();
        let body = usize::try_from(body)
            .ok()
            .filter(|&b| b <= left)
            .ok_or_else(|| format!("has an Arrow body of {body} bytes, and {left} are left"))?;
        pos += body;
    }
}

fn read_exact(reader: &mut impl Read, buf: &mut [u8], at: u64) -> Result<(), String> {
    reader.read_exact(buf).map_err(|e| match e.kind() {
        io::ErrorKind::UnexpectedEof => format!("it is truncated: it ends after byte {at}"),
        _ => format!("reading it failed at byte {at}: {e}"),
    })
}

thread_local! {
    /// Set while [`guarded`] runs on this thread: its panics are not printed.
    static QUIET: Cell<bool> = const { Cell::new(false) };
}

/// Runs `f`, turning a panic into an error carrying its message. The
/// panic is not printed; panics elsewhere (other threads, or this one
/// outside `f`) still are, by the hook that was installed before.
pub(crate) fn guarded<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let before = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.with(Cell::get) {
                before(info);
            }
        }));
    });
    let was = QUIET.with(|q| q.replace(true));
    let result = catch_unwind(AssertUnwindSafe(f));
    QUIET.with(|q| q.set(was));
    result.map_err(|payload| {
        payload
            .downcast_ref::<&str>()
            .map(|s| (*s).to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "a panic without a message".into())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_in_guarded_is_an_error_with_its_message() {
        let r: Result<(), String> = guarded(|| panic!("bad offsets"));
        assert_eq!(r.unwrap_err(), "bad offsets");
        assert_eq!(guarded(|| 3), Ok(3));
    }

    #[test]
    fn a_message_longer_than_the_file_is_refused_before_any_allocation() {
        let mut file = b"RRF2\x00\x24\x03\x00\x01\x02\x00\x00".to_vec();
        file.extend(2u64.to_le_bytes());
        file.extend((u64::MAX / 2).to_le_bytes());
        file.extend([0u8; 40]);
        let len = file.len() as u64;
        let e = check(&mut io::Cursor::new(file), len).unwrap_err();
        assert!(e.contains("message at byte 12 says it is"), "{e}");
    }

    #[test]
    fn a_stream_footer_must_have_one_entry() {
        let mut footer = [0u8; 32];
        footer[20..28].copy_from_slice(b"RRF2FOOT");
        footer[28] = 1;
        rrd_footer(&footer, 100).unwrap();
        footer[31] = 0x80;
        let e = rrd_footer(&footer, 100).unwrap_err();
        assert!(e.contains("stream footer at byte 100"), "{e}");
    }

    #[test]
    fn an_unknown_kind_and_bad_options_are_refused() {
        let mut file = b"RRF2\x00\x24\x03\x00\x01\x02\x00\x00".to_vec();
        file.extend(9u64.to_le_bytes());
        file.extend(0u64.to_le_bytes());
        let len = file.len() as u64;
        let e = check(&mut io::Cursor::new(file.clone()), len).unwrap_err();
        assert!(e.contains("unknown kind 9"), "{e}");
        file[9] = 7;
        let e = check(&mut io::Cursor::new(file), len).unwrap_err();
        assert!(e.contains("encoding options"), "{e}");
    }

    #[test]
    fn an_arrow_message_stating_more_than_its_bytes_can_hold_is_refused() {
        let msg = ArrowMsg {
            compression: Compression::Lz4.into(),
            uncompressed_size: 1 << 40,
            payload: vec![0u8; 100].into(),
            ..Default::default()
        };
        let e = arrow_message(&msg.encode_to_vec(), 12).unwrap_err();
        assert!(e.contains("100 compressed bytes hold 1099511627776"), "{e}");
    }

    #[test]
    fn an_arrow_stream_stating_more_than_it_holds_is_refused() {
        let mut data = vec![0xff; 4];
        data.extend(1_000_000i32.to_le_bytes());
        data.extend([0u8; 64]);
        let e = ipc_stream(&data).unwrap_err();
        assert_eq!(e, "has Arrow metadata of 1000000 bytes, and 64 are left");
        let mut end = vec![0xff; 4];
        end.extend(0i32.to_le_bytes());
        ipc_stream(&end).unwrap();
        ipc_stream(&[]).unwrap();
    }
}
