//! Planar 2-DOF glider mechanisms of the comparative study (Wenger, Gosselin, Chablat 2001):
//! biglide1, biglide2 and orthoglide, as a library. Conventions in docs/gliders.md.

pub mod adaptive;
pub mod design;
pub mod jacobian;
pub mod kinematics;
pub mod spec;
pub mod tolerance;
pub mod verdict;
pub mod workspace;

pub use design::{
    Architecture, DesignOptions, Dimensions, MAX_STRUT_LENGTH_MM, PaperTable1, PaperTable2,
    Table1Row, Table2Row, Target, architecture_spec, design_spec, dimension, envelope, table1,
    table1_row, table2,
};
pub use jacobian::{
    Amplification, Jacobians, amplification, det_a, det_b, is_parallel_singular,
    is_serial_singular, jacobians,
};
pub use kinematics::{
    Branch, FkSolution, ForwardKinematics, IkSolution, WorkingMode, assembly_of,
    forward_kinematics, forward_kinematics_in_mode, inverse_kinematics, inverse_kinematics_in_mode,
    working_mode_of,
};
pub use spec::{GliderSpec, GliderSpecError, PRESET_NAMES, SpecProblem};
pub use verdict::{
    Verdict, WORKING_ASSEMBLY, WORKING_MODE, branch_label, compatible, is_structural, mode_label,
    verdict,
};
pub use workspace::{
    AreaEstimate, NodeClass, PAPER_LAMBDA_BOUNDS, Rectangle, Sampling, WorkspaceGrid,
    WorkspaceOptions, largest_rectangle, largest_square, sample_workspace,
};
