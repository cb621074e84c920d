//! Serde for the large flat arrays (positions, triangles, CSR rings) as their raw bytes: a
//! model goes from an engine worker to the page whole, and the page decodes it on the thread
//! that draws. Element by element (postcard's varints) that took several frames for a brain
//! mesh; as bytes it is a copy. Both ends are the same build on the same machine, so the byte
//! order is theirs. Use with `#[serde(with = "crate::mesh::flat_bytes")]`.

use std::fmt;
use std::marker::PhantomData;

use bytemuck::Pod;
use serde::de::{Error, SeqAccess, Visitor};
use serde::{Deserializer, Serializer};

pub fn serialize<T: Pod, S: Serializer>(values: &[T], serializer: S) -> Result<S::Ok, S::Error> {
    serializer.serialize_bytes(bytemuck::cast_slice(values))
}

pub fn deserialize<'de, T: Pod, D: Deserializer<'de>>(deserializer: D) -> Result<Vec<T>, D::Error> {
    deserializer.deserialize_bytes(FlatVisitor(PhantomData))
}

struct FlatVisitor<T>(PhantomData<T>);

impl<T: Pod> FlatVisitor<T> {
    fn from_bytes<E: Error>(bytes: &[u8]) -> Result<Vec<T>, E> {
        let size = std::mem::size_of::<T>();
        if size == 0 || !bytes.len().is_multiple_of(size) {
            return Err(E::custom(format!(
                "{} bytes are no whole number of {size}-byte elements",
                bytes.len()
            )));
        }
        // A copy into memory aligned for `T` (the wire's bytes need not be).
        Ok(bytemuck::pod_collect_to_vec(bytes))
    }
}

impl<'de, T: Pod> Visitor<'de> for FlatVisitor<T> {
    type Value = Vec<T>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "an array's bytes")
    }

    fn visit_bytes<E: Error>(self, bytes: &[u8]) -> Result<Vec<T>, E> {
        Self::from_bytes(bytes)
    }

    fn visit_byte_buf<E: Error>(self, bytes: Vec<u8>) -> Result<Vec<T>, E> {
        Self::from_bytes(&bytes)
    }

    /// Formats without bytes (JSON) write them as a sequence of numbers.
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Vec<T>, A::Error> {
        let mut bytes = Vec::with_capacity(seq.size_hint().unwrap_or(0).min(1 << 20));
        while let Some(b) = seq.next_element::<u8>()? {
            bytes.push(b);
        }
        Self::from_bytes(&bytes)
    }
}

#[cfg(test)]
mod tests {
    use serde::{Deserialize, Serialize};

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Arrays {
        #[serde(with = "super")]
        points: Vec<[f32; 3]>,
        #[serde(with = "super")]
        indices: Vec<u32>,
        name: String,
    }

    #[test]
    fn arrays_go_as_bytes_and_come_back_the_same() {
        let a = Arrays {
            points: vec![[1.5, -0.0, f32::MAX], [f32::MIN_POSITIVE, 2.0, 3.0]],
            indices: vec![0, u32::MAX, 7],
            name: "x".into(),
        };
        let wire = postcard::to_allocvec(&a).unwrap();
        // Two lengths, the raw bytes and the name: no varint per element.
        assert_eq!(wire.len(), 1 + 24 + 1 + 12 + 1 + 1);
        assert_eq!(postcard::from_bytes::<Arrays>(&wire).unwrap(), a);
        let json = serde_json::to_string(&a).unwrap();
        assert_eq!(serde_json::from_str::<Arrays>(&json).unwrap(), a);
    }

    #[test]
    fn a_length_that_splits_an_element_is_refused() {
        // Five bytes of points (12 bytes each), no indices, the name "x".
        let wire = [5, 1, 2, 3, 4, 5, 0, 1, b'x'];
        assert!(postcard::from_bytes::<Arrays>(&wire).is_err());
        let whole = [12, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, b'x'];
        assert!(postcard::from_bytes::<Arrays>(&whole).is_ok());
    }
}
