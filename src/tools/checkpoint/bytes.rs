//! A checkpoint as bytes: the format's name first (what the file is, read before anything
//! else), the fields in postcard's compact form, and a CRC-32 of all of them at the end, so that
//! a byte changed, cut or added since the file was written is refused as damaged.

use std::io::Read;
use std::path::Path;

use super::{Checkpoint, MAX_CHECKPOINT_BYTES};
use crate::base::error::InputError;
use crate::tools::io::read_bytes_limited;

/// The first field of every checkpoint: what it is and the layout's version.
pub(super) const FORMAT: &str = "moving_circles checkpoint 10";
/// What ends a checkpoint: the CRC-32 (IEEE) of every byte before it, little-endian.
pub(super) const CHECKSUM_BYTES: usize = 4;
/// Bytes read before the format is checked: any format name of ours, with its length, fits.
const HEAD_BYTES: u64 = 64;
/// Whether `bytes` begin with the name of this checkpoint format; says what they are if not.
fn check_format(bytes: &[u8], origin: &str) -> Result<(), InputError> {
    let not_one = || InputError::whole(origin, "not a moving_circles checkpoint");
    let (format, _) = postcard::take_from_bytes::<String>(bytes).map_err(|_| not_one())?;
    match format.as_str() {
        FORMAT => Ok(()),
        other if other.starts_with("moving_circles checkpoint") => Err(InputError::whole(
            origin,
            format!(
                "written by another version ({}), this one reads `{FORMAT}`",
                crate::base::error::printable(other)
            ),
        )),
        _ => Err(not_one()),
    }
}

impl Checkpoint {
    /// The checkpoint as bytes: its fields, then their checksum.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut bytes = postcard::to_stdvec(self).expect("a checkpoint is plain data");
        let checksum = crc32fast::hash(&bytes);
        bytes.extend_from_slice(&checksum.to_le_bytes());
        bytes
    }

    /// Reads and checks a checkpoint file. Its first bytes are checked before the rest is read:
    /// a file of another kind (a device, an endless stream) is refused after a few bytes.
    pub fn read(path: &Path) -> Result<Self, InputError> {
        let origin = path.display().to_string();
        let cannot_read =
            |e: std::io::Error| InputError::whole(&origin, format!("cannot read: {e}"));
        let mut file = std::fs::File::open(path).map_err(cannot_read)?;
        let mut bytes = Vec::new();
        (&mut file)
            .take(HEAD_BYTES)
            .read_to_end(&mut bytes)
            .map_err(cannot_read)?;
        check_format(&bytes, &origin)?;
        let rest = read_bytes_limited(file, MAX_CHECKPOINT_BYTES - bytes.len() as u64)
            .map_err(cannot_read)?
            .ok_or_else(|| {
                InputError::whole(
                    &origin,
                    format!(
                        "larger than the {} GiB a checkpoint may have",
                        MAX_CHECKPOINT_BYTES >> 30
                    ),
                )
            })?;
        bytes.extend_from_slice(&rest);
        Self::from_bytes(&bytes, &origin)
    }

    /// Reads and checks checkpoint bytes; `origin` names them in errors. The format comes
    /// first, then the checksum over every byte (a byte changed, cut or added since the file
    /// was written is refused), then every value.
    pub fn from_bytes(bytes: &[u8], origin: &str) -> Result<Self, InputError> {
        let damaged =
            |what: String| InputError::whole(origin, format!("damaged checkpoint: {what}"));
        check_format(bytes, origin)?;
        let Some(end) = bytes.len().checked_sub(CHECKSUM_BYTES) else {
            return Err(damaged("cut short before its checksum".to_owned()));
        };
        let (fields, checksum) = bytes.split_at(end);
        if crc32fast::hash(fields).to_le_bytes() != checksum {
            return Err(damaged(
                "its checksum does not match its bytes (changed, cut short or lengthened since \
                 it was written)"
                    .to_owned(),
            ));
        }
        let (checkpoint, past): (Self, _) =
            postcard::take_from_bytes(fields).map_err(|e| damaged(e.to_string()))?;
        if !past.is_empty() {
            let bytes = if past.len() == 1 { "byte" } else { "bytes" };
            return Err(damaged(format!(
                "{} {bytes} past its last field",
                past.len()
            )));
        }
        checkpoint
            .check()
            .map_err(|message| InputError::whole(origin, message))?;
        Ok(checkpoint)
    }

    /// Makes the checksum that ends `bytes` the one of the bytes before it (nothing if they are
    /// too few to hold one): the checkpoint fuzz target reseals each mutated input, so that its
    /// changes reach the checks of every value behind the checksum. A resealed file is only as
    /// good as its maker.
    pub fn reseal(bytes: &mut [u8]) {
        if let Some(end) = bytes.len().checked_sub(CHECKSUM_BYTES) {
            let checksum = crc32fast::hash(&bytes[..end]);
            bytes[end..].copy_from_slice(&checksum.to_le_bytes());
        }
    }
}
