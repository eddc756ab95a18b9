//! Work coordinates on the parser state: turning a line's X and Y into a machine target, and the
//! non-modal commands that set or use the coordinate data ([`super::offsets`]): G10 L2 / L20,
//! G28 / G30 and their `.1` forms, G92 and G92.1, with GRBL's rules and error numbers.

use super::offsets::StoredPosition;
use super::words::{NonModal, Words};
use super::{Commands, Distance, GcodeState, WORK_SYSTEMS, WorkSystem};
use crate::host::GrblError;
use crate::motion::job::Feed;
use crate::settings::Settings;

/// G10's L for "set the offset to the axis values" (L2).
const G10_SET_OFFSET: f32 = 2.0;
/// G10's L for "set the offset so the planned position has the axis values" (L20).
const G10_SET_HERE: f32 = 20.0;

impl GcodeState {
    /// The machine target (mm) of a line's axis values `axis` (mm, `None` where the line has no
    /// word): absolute work coordinates plus the active system's and the G92 offset, or relative
    /// to the planned position, or machine coordinates as they are (G53). An axis without a word
    /// stays where it is planned.
    pub(super) fn target_mm(&self, axis: [Option<f32>; 2], distance: Distance, machine: bool) -> [f32; 2] {
        let offset = self.work_offset_mm();
        let mut target = self.position_mm;
        for (i, v) in axis.iter().enumerate() {
            if let Some(v) = *v {
                target[i] = match (machine, distance) {
                    (true, _) => v,
                    (false, Distance::Absolute) => v + offset[i],
                    (false, Distance::Incremental) => self.position_mm[i] + v,
                };
            }
        }
        target
    }

    /// The coordinate data part of a line's non-modal `command` (G10, G28.1, G30.1, G92,
    /// G92.1; nothing for the others), with the line's axis values `axis` (mm). G10 takes its L
    /// and P (and refuses an R) from `words`.
    pub(super) fn set_coordinates(
        &mut self,
        command: NonModal,
        words: &mut Words,
        axis: [Option<f32>; 2],
        has_axis: bool,
    ) -> Result<(), GrblError> {
        match command {
            NonModal::SetSystem => self.set_system(words, axis, has_axis)?,
            NonModal::Store(which) => self.offsets.store(which, self.position_mm),
            NonModal::SetOffset => {
                if !has_axis {
                    return Err(GrblError::NoAxisWords);
                }
                // The planned position becomes the given work position: G92 = machine - system - work.
                let system = self.offsets.system_mm(self.work_system);
                let mut g92 = self.offsets.g92_mm();
                for (i, v) in axis.iter().enumerate() {
                    if let Some(v) = v {
                        g92[i] = self.position_mm[i] - system[i] - v;
                    }
                }
                self.offsets.set_g92_mm(g92);
            }
            NonModal::ClearOffset => self.offsets.set_g92_mm([0.0; 2]),
            NonModal::Dwell | NonModal::MachineCoords | NonModal::GoToStored(_) => {}
        }
        Ok(())
    }

    /// G10 L2 / L20 P: sets one system's offset, on the axes the line names.
    fn set_system(&mut self, words: &mut Words, axis: [Option<f32>; 2], has_axis: bool) -> Result<(), GrblError> {
        if !has_axis {
            return Err(GrblError::NoAxisWords);
        }
        let (Some(l), Some(p)) = (words.take(b'L'), words.take(b'P')) else {
            return Err(GrblError::ValueWordMissing);
        };
        let system = self.system_of_p(p)?;
        let set_here = l == G10_SET_HERE;
        if !set_here && l != G10_SET_OFFSET {
            return Err(GrblError::Unsupported);
        }
        if !set_here && words.get(b'R').is_some() {
            // LinuxCNC's rotation of a coordinate system.
            return Err(GrblError::Unsupported);
        }
        let g92 = self.offsets.g92_mm();
        let mut offset = self.offsets.system_mm(system);
        for (i, v) in axis.iter().enumerate() {
            if let Some(v) = *v {
                // L20: the planned position becomes the given work position under this system.
                offset[i] = if set_here { self.position_mm[i] - g92[i] - v } else { v };
            }
        }
        self.offsets.set_system_mm(system, offset);
        Ok(())
    }

    /// The system G10's P names: 0 the active one, 1 to 6 G54 to G59 (error 29 otherwise; P is
    /// never negative, the parser refused that).
    fn system_of_p(&self, p: f32) -> Result<WorkSystem, GrblError> {
        let n = crate::math::round(p);
        if n != p || !(n <= WORK_SYSTEMS as f32) {
            return Err(GrblError::UnsupportedCoordSys);
        }
        if n == 0.0 {
            return Ok(self.work_system);
        }
        WorkSystem::from_index(n as usize - 1).ok_or(GrblError::UnsupportedCoordSys)
    }

    /// G28 / G30: rapid to the stored position (machine coordinates), first through the
    /// intermediate point the axis words give (work coordinates, G90/G91 as set). With axis words
    /// only the axes they name go on to the stored position, as in GRBL. The two moves go into
    /// `out` (its `via` and `main`), either none where it goes nowhere.
    pub(super) fn go_to_stored(
        &mut self,
        which: StoredPosition,
        axis: [Option<f32>; 2],
        has_axis: bool,
        settings: &Settings,
        out: &mut Commands,
    ) -> Result<(), GrblError> {
        let stored = self.offsets.stored_mm(which);
        if !has_axis {
            return self.line(stored, Feed::Rapid, settings, &mut out.main);
        }
        let start = self.position_mm;
        let via = self.target_mm(axis, self.distance, false);
        let end = [0, 1].map(|i| if axis[i].is_some() { stored[i] } else { start[i] });
        self.line(via, Feed::Rapid, settings, &mut out.via)?;
        self.line(end, Feed::Rapid, settings, &mut out.main)
    }
}
