//! The one request convention (crate docs, "Requests"): `new` takes what a
//! workflow cannot do without; every other field has a default and a
//! chainable setter of its own name, generated here ([`setters!`]) so that
//! every request's builder is the same code.

/// Chainable setters of a request's fields, one per field, each named as
/// its field: `name: Type` sets the value, `name: into Type` takes any
/// `impl Into<Type>`, and `some` sets an optional field to `Some(value)`.
/// Each field is followed by a comma.
macro_rules! setters {
    ($request:ident {}) => {};
    ($request:ident { $field:ident: some into $ty:ty, $($rest:tt)* }) => {
        $crate::request::setters!(@one $request $field "`Some(value)`",
            (value: impl Into<$ty>) Some(value.into()));
        $crate::request::setters!($request { $($rest)* });
    };
    ($request:ident { $field:ident: some $ty:ty, $($rest:tt)* }) => {
        $crate::request::setters!(@one $request $field "`Some(value)`", (value: $ty) Some(value));
        $crate::request::setters!($request { $($rest)* });
    };
    ($request:ident { $field:ident: into $ty:ty, $($rest:tt)* }) => {
        $crate::request::setters!(@one $request $field "`value`",
            (value: impl Into<$ty>) value.into());
        $crate::request::setters!($request { $($rest)* });
    };
    ($request:ident { $field:ident: $ty:ty, $($rest:tt)* }) => {
        $crate::request::setters!(@one $request $field "`value`", (value: $ty) value);
        $crate::request::setters!($request { $($rest)* });
    };
    // One setter: `$value: $param` in, `$set` stored.
    (@one $request:ident $field:ident $what:literal, ($value:ident: $($param:tt)+) $set:expr) => {
        impl $request {
            #[doc = concat!("Sets [`", stringify!($request), "::", stringify!($field),
                "`] to ", $what, ": a chainable setter.")]
            #[must_use]
            pub fn $field(mut self, $value: $($param)+) -> $request {
                self.$field = $set;
                self
            }
        }
    };
}
pub(crate) use setters;
