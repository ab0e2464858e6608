classdef fricont_handle < handle
%FRICONT_HANDLE Owner of a library path handle (a checked uint64 id of fricont_mex).
%   Created by FRICONT_TRACE; the library path is freed when the last reference to this
%   object is cleared, or by calling delete on it.
  properties (SetAccess = private)
    id = uint64(0);
  end
  methods
    function obj = fricont_handle(id)
      obj.id = id;
    end
    function delete(obj)
      if obj.id ~= 0
        try
          fricont_mex('free', obj.id);
        catch
          % never raise from a destructor
        end
        obj.id = uint64(0);
      end
    end
  end
end
