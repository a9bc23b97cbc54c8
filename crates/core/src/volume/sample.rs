//! One sample: the types a volume keeps its samples in ([`SampleType`])
//! and what a path asks of each ([`Sample`]: its exact `f32`, whether it
//! is finite). A volume's store of them and its samples of any type are
//! built on these.

/// The types a volume keeps its samples in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum SampleType {
    U8,
    I8,
    U16,
    I16,
    F32,
}

impl SampleType {
    /// Bytes a sample takes.
    pub fn bytes(self) -> usize {
        match self {
            SampleType::U8 | SampleType::I8 => 1,
            SampleType::U16 | SampleType::I16 => 2,
            SampleType::F32 => 4,
        }
    }

    /// The usual name: `u8`, `i8`, `u16`, `i16`, `f32`.
    pub fn name(self) -> &'static str {
        match self {
            SampleType::U8 => "u8",
            SampleType::I8 => "i8",
            SampleType::U16 => "u16",
            SampleType::I16 => "i16",
            SampleType::F32 => "f32",
        }
    }
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for u8 {}
    impl Sealed for i8 {}
    impl Sealed for u16 {}
    impl Sealed for i16 {}
    impl Sealed for f32 {}
}

/// A sample type a volume can hold: read as the `f32` it converts to
/// exactly.
pub trait Sample:
    bytemuck::Pod + Send + Sync + PartialOrd + Default + 'static + sealed::Sealed
{
    const TYPE: SampleType;

    /// The sample's value (exact for every type here).
    fn to_f32(self) -> f32;

    /// Whether it is a finite number (integers always are).
    #[inline(always)]
    fn is_finite(self) -> bool {
        true
    }
}

impl Sample for u8 {
    const TYPE: SampleType = SampleType::U8;
    #[inline(always)]
    fn to_f32(self) -> f32 {
        f32::from(self)
    }
}

impl Sample for i8 {
    const TYPE: SampleType = SampleType::I8;
    #[inline(always)]
    fn to_f32(self) -> f32 {
        f32::from(self)
    }
}

impl Sample for u16 {
    const TYPE: SampleType = SampleType::U16;
    #[inline(always)]
    fn to_f32(self) -> f32 {
        f32::from(self)
    }
}

impl Sample for i16 {
    const TYPE: SampleType = SampleType::I16;
    #[inline(always)]
    fn to_f32(self) -> f32 {
        f32::from(self)
    }
}

impl Sample for f32 {
    const TYPE: SampleType = SampleType::F32;
    #[inline(always)]
    fn to_f32(self) -> f32 {
        self
    }
    #[inline(always)]
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
}
