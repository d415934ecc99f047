//! The door's pages of the terms an extended model is made of (an effect
//! of the vocabulary or a generic term) and the campaign's frame they are
//! judged in, re-exported by [`crate::diagnosis`]: kept here so the
//! workflow module stays short.

/// What a campaign offers the generic terms: its legs' and the UP limb's
/// strokes, its time axis, its temperatures, its sensors' directions.
///
/// # Example
/// ```
/// use tricept_ident::diagnosis::{Frame, Term};
/// use tricept_ident::effects::{EffectName, Needs};
/// let nothing = Frame::empty();
/// assert!(nothing.supports(Needs::Nothing) && !nothing.supports(Needs::Temperature));
/// assert!(!nothing.supports(Needs::LegStrokes)); // no leg moved
/// let warm = Frame { temperature: Some([21.0, 20.0, 22.0]), ..Frame::empty() };
/// assert!(warm.supports(Needs::Temperature));
/// assert!(Term::Catalogue(EffectName::LegLead).available(&nothing));
/// ```
#[doc(inline)]
pub use tricept_diagnose::terms::Frame;
/// A generic term: a family, the legs or channel it acts on, and the
/// period or edges a scan found for it.
///
/// # Example
/// ```
/// use tricept_ident::diagnosis::{GenericTerm, Scope};
/// use tricept_ident::effects::GenericFamily;
/// let mut periodic = GenericTerm::new(GenericFamily::LegPeriodic, Scope::AllLegs);
/// assert!(!periodic.is_scanned()); // no period yet
/// periodic.period_mm = Some(10.0);
/// assert!(periodic.is_scanned() && periodic.acts_on_legs());
/// assert_eq!(periodic.legs(), [0, 1, 2]);
/// assert_eq!(periodic.label(), "leg-periodic:legs@10.000mm");
/// ```
#[doc(inline)]
pub use tricept_diagnose::terms::GenericTerm;
/// A campaign's time axis: the logged time (`time_s`) or the file's lines,
/// and its first and last values.
///
/// # Example
/// ```
/// use tricept_ident::diagnosis::{Frame, OrderAxis};
/// use tricept_ident::effects::Needs;
/// let hour = OrderAxis { uses_time: true, first: 0.0, last: 3600.0 };
/// let ordered = Frame { order: Some(hour), ..Frame::empty() };
/// assert!(ordered.supports(Needs::PoseOrder));
/// assert!(!Frame::empty().supports(Needs::PoseOrder));
/// ```
#[doc(inline)]
pub use tricept_diagnose::terms::OrderAxis;
/// The legs or reading channel a generic term acts on (0-based: leg 0 is
/// leg 1; channels 0 `phi`, 1 `theta`, 2 `s`).
///
/// # Example
/// ```
/// use tricept_ident::diagnosis::{GenericTerm, Scope};
/// use tricept_ident::effects::GenericFamily;
/// let gain = GenericTerm::new(GenericFamily::EncoderGain, Scope::Channel(0));
/// assert_eq!((gain.channel(), gain.legs()), (Some(0), vec![]));
/// let step = GenericTerm::new(GenericFamily::LegStep, Scope::Leg(1));
/// assert_eq!((step.channel(), step.legs()), (None, vec![1]));
/// ```
#[doc(inline)]
pub use tricept_diagnose::terms::Scope;
/// A term of an extended model: an effect of the vocabulary, or a generic
/// term.
///
/// # Example
/// ```
/// use tricept_ident::diagnosis::{GenericTerm, Scope, Term};
/// use tricept_ident::effects::{EffectName, GenericFamily};
/// let lead = Term::Catalogue(EffectName::LegLead);
/// assert_eq!(lead.name().to_string(), "leg-lead");
/// assert_eq!(lead.param_count(), 3); // one lead per leg
/// let drift = Term::Generic(GenericTerm::new(GenericFamily::ReadingDrift, Scope::Channel(2)));
/// assert_eq!(drift.params(), ["s_um"]);
/// assert_eq!(drift.label(), "reading-drift:s");
/// ```
#[doc(inline)]
pub use tricept_diagnose::terms::Term;
