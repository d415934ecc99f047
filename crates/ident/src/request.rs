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
        impl $request {
            #[doc = concat!("Sets [`", stringify!($request), "::", stringify!($field),
                "`] to `Some(value)`: a chainable setter.")]
            #[must_use]
            pub fn $field(mut self, value: impl Into<$ty>) -> $request {
                self.$field = Some(value.into());
                self
            }
        }
        $crate::request::setters!($request { $($rest)* });
    };
    ($request:ident { $field:ident: some $ty:ty, $($rest:tt)* }) => {
        impl $request {
            #[doc = concat!("Sets [`", stringify!($request), "::", stringify!($field),
                "`] to `Some(value)`: a chainable setter.")]
            #[must_use]
            pub fn $field(mut self, value: $ty) -> $request {
                self.$field = Some(value);
                self
            }
        }
        $crate::request::setters!($request { $($rest)* });
    };
    ($request:ident { $field:ident: into $ty:ty, $($rest:tt)* }) => {
        impl $request {
            #[doc = concat!("Sets [`", stringify!($request), "::", stringify!($field),
                "`]: a chainable setter.")]
            #[must_use]
            pub fn $field(mut self, value: impl Into<$ty>) -> $request {
                self.$field = value.into();
                self
            }
        }
        $crate::request::setters!($request { $($rest)* });
    };
    ($request:ident { $field:ident: $ty:ty, $($rest:tt)* }) => {
        impl $request {
            #[doc = concat!("Sets [`", stringify!($request), "::", stringify!($field),
                "`]: a chainable setter.")]
            #[must_use]
            pub fn $field(mut self, value: $ty) -> $request {
                self.$field = value;
                self
            }
        }
        $crate::request::setters!($request { $($rest)* });
    };
}
pub(crate) use setters;
