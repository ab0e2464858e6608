//! Node classes (SPEC §3).

/// The class of a contact node on a smooth piece.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[repr(u8)]
pub enum Class {
    /// No contact: `λν = λt = 0`, guard `dν < 0`.
    Open = 0,
    /// Contact, stick: `dν = dt = 0`, guards `λν < 0`, `F λν < λt < −F λν` (never at a
    /// frictionless node, F = 0: its region is empty there).
    Stick = 1,
    /// Contact, slip in +t: `dν = 0`, `λt = F λν`, guards `λν < 0`, `dt > 0`. A
    /// frictionless node in contact is in S+ or S− by the sign of its dt; where dt stays
    /// at zero it keeps the sign it had (S+ where it touched down so).
    SlipPlus = 2,
    /// Contact, slip in −t: `dν = 0`, `λt = −F λν`, guards `λν < 0`, `dt < 0`.
    SlipMinus = 3,
}

impl Class {
    /// All four classes, in the order of their discriminants.
    pub const ALL: [Class; 4] = [Class::Open, Class::Stick, Class::SlipPlus, Class::SlipMinus];

    /// The exchange-format name: `"open"`, `"stick"`, `"slip+"`, `"slip-"`.
    pub fn name(self) -> &'static str {
        match self {
            Class::Open => "open",
            Class::Stick => "stick",
            Class::SlipPlus => "slip+",
            Class::SlipMinus => "slip-",
        }
    }

    /// The seed paper's words: "no contact", "contact, stick", "contact, slip".
    pub fn words(self) -> &'static str {
        match self {
            Class::Open => "no contact",
            Class::Stick => "contact, stick",
            Class::SlipPlus | Class::SlipMinus => "contact, slip",
        }
    }

    /// Parses the exchange-format name.
    pub fn from_name(s: &str) -> Option<Class> {
        Class::ALL.into_iter().find(|c| c.name() == s)
    }

    /// True for the three contact classes.
    pub fn in_contact(self) -> bool {
        self != Class::Open
    }
}

impl std::fmt::Display for Class {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}
