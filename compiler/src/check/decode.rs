//! The channel attributes that say how the engine stores a channel:
//! `@depth(U)` (a `float3` position rebuilt from a depth texture and the
//! `float4x4` uniform `U`, the inverse view-projection) and
//! `@encoded(unorm | octahedral | octahedral_unorm)` (normals packed as
//! engines pack them) and `@packed(bevy_deferred, FIELD)` (one field of
//! Bevy's deferred G-buffer). The kernels decode in the channel's loader.

use super::{Checker, InputId, UniformKind, err};
use crate::syntax::ast::*;
use crate::types::{Scalar, Type};
use mrsl_abi::{BevyField, Decode};

/// The encodings `@encoded` takes, with what each means in messages.
const ENCODINGS: [(&str, &str); 3] = [
    ("unorm", "stored 0 to 1, read as 2v - 1"),
    ("octahedral", "a unit float3 as two octahedral components in -1 to 1"),
    ("octahedral_unorm", "the same, stored 0 to 1"),
];

impl Checker<'_> {
    /// Records the decoding `attr` asks of channel `id` (of type `ty`), or reports why it cannot be.
    pub(super) fn channel_decode(&mut self, id: InputId, attr: &Attribute, ty: &Type) {
        let decode = match attr.name.name.as_str() {
            "depth" => self.depth_decode(attr, ty),
            "packed" => self.packed(attr, ty),
            _ => self.encoded(attr, ty),
        };
        let Some(decode) = decode else { return };
        if self.out.inputs[id.index()].decode.is_some() {
            self.error(
                err("E0111", "a channel is decoded one way", attr.span, "a second decoding")
                    .with_note("`@depth`, `@encoded` and `@packed` are each a whole decoding of the channel"),
            );
            return;
        }
        self.out.inputs[id.index()].decode = Some(decode);
    }

    /// `@depth(inverse_view_projection)` on a `float3` channel.
    fn depth_decode(&mut self, attr: &Attribute, ty: &Type) -> Option<Decode> {
        let [matrix] = attr.args.as_slice() else {
            self.error(
                err("E0111", "`@depth` takes the inverse view-projection uniform", attr.span, "expected one argument")
                    .with_note("e.g. `uniform float4x4 inverse_view_proj;` and `@depth(inverse_view_proj) in float3 position;`"),
            );
            return None;
        };
        if *ty != Type::Vector(Scalar::Float, 3) && !ty.is_error() {
            self.error(err("E0111", "`@depth` rebuilds a `float3` position channel", attr.span, "not a `float3`"));
            return None;
        }
        let uniform = match &matrix.kind {
            ExprKind::Name(name) => self.out.uniforms.iter().find(|u| u.name == *name),
            _ => None,
        };
        match uniform {
            Some(u) if u.ty == Type::Matrix(4) && matches!(u.kind, UniformKind::Value { .. }) => {
                Some(Decode::Depth { inverse_view_projection: u.name.clone() })
            }
            _ => {
                self.error(
                    err("E0111", "`@depth` takes a `uniform float4x4`", matrix.span, "not a `float4x4` uniform")
                        .with_note("the inverse of the view-projection the depth was rendered with, set by the engine"),
                );
                None
            }
        }
    }

    /// `@packed(bevy_deferred, FIELD)`: the channel is FIELD of Bevy's
    /// deferred G-buffer, and has FIELD's type.
    fn packed(&mut self, attr: &Attribute, ty: &Type) -> Option<Decode> {
        let fields = || {
            let list: Vec<String> = BevyField::ALL.iter().map(|(_, name, ty)| format!("`{name}` ({ty})")).collect();
            format!("the fields of `bevy_deferred`: {}", list.join(", "))
        };
        let name = |e: &Expr| match &e.kind {
            ExprKind::Name(name) => Some(name.clone()),
            _ => None,
        };
        let [preset, field] = attr.args.as_slice() else {
            self.error(
                err("E0111", "`@packed` takes a packing and a field", attr.span, "expected two arguments")
                    .with_note("e.g. `@packed(bevy_deferred, normal) in float3 normal;`"),
            );
            return None;
        };
        if name(preset).as_deref() != Some("bevy_deferred") {
            self.error(
                err("E0111", "unknown packing", preset.span, "not a packing")
                    .with_note("the packings: `bevy_deferred` (Bevy's deferred G-buffer, an `Rgba32Uint` texture)"),
            );
            return None;
        }
        let Some(&(field, _, wanted)) = BevyField::ALL.iter().find(|(_, n, _)| name(field).as_deref() == Some(*n))
        else {
            self.error(err("E0111", "unknown field of `bevy_deferred`", field.span, "not a field").with_note(fields()));
            return None;
        };
        if ty.to_string() != wanted && !ty.is_error() {
            self.error(
                err(
                    "E0111",
                    format!("this field of `bevy_deferred` is a `{wanted}`"),
                    attr.span,
                    format!("declare the channel `{wanted}`"),
                )
                .with_note(fields()),
            );
            return None;
        }
        Some(Decode::BevyDeferred { field })
    }

    /// `@encoded(unorm)` on a float channel, `@encoded(octahedral)` and
    /// `@encoded(octahedral_unorm)` on a `float3` one.
    fn encoded(&mut self, attr: &Attribute, ty: &Type) -> Option<Decode> {
        let known = || {
            let list: Vec<String> = ENCODINGS.iter().map(|(name, what)| format!("`{name}` ({what})")).collect();
            format!("the encodings: {}", list.join(", "))
        };
        let name = match attr.args.as_slice() {
            [arg] => match &arg.kind {
                ExprKind::Name(name) if ENCODINGS.iter().any(|(n, _)| n == name) => name.clone(),
                _ => {
                    self.error(err("E0111", "unknown encoding", arg.span, "not an encoding").with_note(known()));
                    return None;
                }
            },
            _ => {
                self.error(
                    err("E0111", "`@encoded` takes one encoding", attr.span, "expected one argument")
                        .with_note(known()),
                );
                return None;
            }
        };
        let float3 = Type::Vector(Scalar::Float, 3);
        if ty.is_error() {
            return None;
        }
        let decode = match name.as_str() {
            "unorm" if ty.scalar() == Some(Scalar::Float) => Decode::Unorm,
            "unorm" => {
                self.error(err("E0111", "`@encoded(unorm)` decodes a float channel", attr.span, "not a float channel"));
                return None;
            }
            _ if *ty != float3 => {
                self.error(err(
                    "E0111",
                    "an octahedral encoding decodes a `float3` channel",
                    attr.span,
                    "not a `float3`",
                ));
                return None;
            }
            "octahedral" => Decode::Octahedral,
            _ => Decode::OctahedralUnorm,
        };
        Some(decode)
    }
}
