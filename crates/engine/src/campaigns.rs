//! The campaigns of a pooled data set: the poses of one campaign share the
//! sensors' three zero offsets, each campaign has its own
//! ([`tricept_data::MeasuredPose::campaign`]). A data set of one file is
//! one campaign and every fit is as it always was; a pooled one has three
//! offset unknowns per campaign, first in every reduced problem, campaign
//! by campaign in ascending campaign number.

use tricept_data::MeasuredPose;

/// The campaigns present in a set of poses, in ascending number.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Campaigns {
    ids: Vec<u32>,
}

impl Campaigns {
    /// The campaigns of `poses` (one pass; the usual single campaign costs
    /// no sort).
    pub(crate) fn of(poses: &[MeasuredPose]) -> Campaigns {
        let first = poses.first().map_or(0, |p| p.campaign);
        if poses.iter().all(|p| p.campaign == first) {
            return Campaigns { ids: vec![first] };
        }
        let mut ids: Vec<u32> = poses.iter().map(|p| p.campaign).collect();
        ids.sort_unstable();
        ids.dedup();
        Campaigns { ids }
    }

    /// The offset unknowns: three per campaign.
    pub(crate) fn nuisance(&self) -> usize {
        3 * self.ids.len()
    }

    /// The campaign numbers, ascending.
    pub(crate) fn ids(&self) -> &[u32] {
        &self.ids
    }

    /// The position of `pose`'s campaign (its offsets are nuisance columns
    /// `3 i .. 3 i + 3`); `None` for a campaign not among these.
    pub(crate) fn index(&self, pose: &MeasuredPose) -> Option<usize> {
        match self.ids.as_slice() {
            [only] => (*only == pose.campaign).then_some(0),
            ids => ids.binary_search(&pose.campaign).ok(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pose(campaign: u32) -> MeasuredPose {
        MeasuredPose {
            campaign,
            ..MeasuredPose::default()
        }
    }

    #[test]
    fn campaigns_are_found_in_ascending_order_and_indexed() {
        let poses = [pose(4), pose(1), pose(4), pose(9)];
        let c = Campaigns::of(&poses);
        assert_eq!(c.ids(), &[1, 4, 9]);
        assert_eq!(c.nuisance(), 9);
        assert_eq!(c.index(&pose(4)), Some(1));
        assert_eq!(c.index(&pose(2)), None);
        let one = Campaigns::of(&[pose(7), pose(7)]);
        assert_eq!((one.index(&pose(7)), one.index(&pose(0))), (Some(0), None));
        assert_eq!(Campaigns::of(&[]).nuisance(), 3);
    }
}
